#include "pipeline/paint/auto_modes.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

namespace fresco {

std::string AutoDecision::Describe() const {
  if (!is_auto()) return "";
  char line[200];
  if (!std::isfinite(evidence)) {
    std::snprintf(line, sizeof line, "%s: no evidence yet%s", StateName(),
                  state == State::kOff ? " (view selection runs without refinement)" : "");
    if (state == State::kDeciding) std::snprintf(line, sizeof line, "deciding: no evidence yet");
    return line;
  }
  const char* relation = evidence > threshold ? ">" : "<=";
  if (state == State::kDeciding)
    std::snprintf(line, sizeof line, "deciding: %.3g %s %.3g over %d frames so far", evidence,
                  relation, threshold, frames_measured);
  else if (basis == "held_out")
    std::snprintf(line, sizeof line,
                  "%s: the mean of every view scores %+.2f dB against the sharpest view "
                  "on %d frames held out (decided at frame %d)",
                  state == State::kOn ? "mean" : "quality", evidence, frames_measured,
                  decided_at_frame);
  else if (basis == "held_out_sharp")
    std::snprintf(line, sizeof line,
                  "sharp_mean: the mean weighted by each view's pixels on the texel scores "
                  "%+.2f dB against the sharpest view on %d frames held out (decided at frame %d)",
                  evidence, frames_measured, decided_at_frame);
  else if (basis == "held_out_without_model")
    std::snprintf(line, sizeof line,
                  "off: the mean of every view without the model scores %+.2f dB against the "
                  "best with it on %d frames held out (decided at frame %d)",
                  evidence, frames_measured, decided_at_frame);
  else if (basis == "held_out_poses")
    std::snprintf(line, sizeof line,
                  "off: the first frames look misaligned, but frames left out of the pose "
                  "corrections agree %.2f times better with the corrected frames (%.2f needed; "
                  "%d frames; decided at frame %d)",
                  evidence, threshold, frames_measured, decided_at_frame);
  else if (basis == "across_views")
    std::snprintf(line, sizeof line,
                  "%s: %.3g %s %.3g of the pixels of %d frames differ from the frames near them "
                  "in regions (decided before painting)",
                  StateName(), evidence, relation, threshold, frames_measured);
  else
    std::snprintf(line, sizeof line, "%s: %.3g %s %.3g over %d frames (decided at frame %d)",
                  StateName(), evidence, relation, threshold, frames_measured, decided_at_frame);
  return line;
}

namespace {

nlohmann::json DecisionJson(const AutoDecision& d) {
  if (!d.is_auto()) return nullptr;
  return {{"decision", d.StateName()},
          {"basis", d.basis.empty() ? nlohmann::json(nullptr) : nlohmann::json(d.basis)},
          {"evidence", std::isfinite(d.evidence) ? nlohmann::json(d.evidence) : nullptr},
          {"threshold", d.threshold},
          {"frames_measured", d.frames_measured},
          {"decided_at_frame", d.decided_at_frame}};
}

}  // namespace

std::string AutoDecisionsJson(const AutoDecisions& decisions) {
  nlohmann::json update = DecisionJson(decisions.update);
  if (decisions.update.is_auto() && decisions.update.state != AutoDecision::State::kDeciding)
    update["decision"] = decisions.update.state != AutoDecision::State::kOn ? "quality"
                         : decisions.update.basis == "held_out_sharp"       ? "sharp_mean"
                                                                            : "mean";
  const nlohmann::json j = {{"refine", DecisionJson(decisions.refine)},
                            {"background", DecisionJson(decisions.background)},
                            {"update", update}};
  return j.dump();
}

void BackgroundAutoDecider::OffByFramesHeldOut(int frame_number, double gain_db, int frames) {
  decision_.state = AutoDecision::State::kOff;
  decision_.basis = "held_out_without_model";
  decision_.evidence = gain_db;
  decision_.threshold = 0;
  decision_.frames_measured = frames;
  decision_.decided_at_frame = frame_number;
}

void RefineAutoDecider::Start(bool enabled) {
  decision_ = AutoDecision();
  samples_.clear();
  if (!enabled) return;
  decision_.state = AutoDecision::State::kDeciding;
  decision_.threshold = kRefineAutoThresholdPx;
}

bool RefineAutoDecider::AddFrame(int frame_number, double misalignment_px) {
  if (!deciding()) return false;
  if (misalignment_px >= 0) {
    samples_.push_back(misalignment_px);
    decision_.frames_measured = static_cast<int>(samples_.size());
    std::vector<double> sorted = samples_;
    std::sort(sorted.begin(), sorted.end());
    const size_t n = sorted.size();
    decision_.evidence = n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
  }
  // Frames that could not be registered to what is painted (too different: photos far
  // apart, plain texture) give nothing to measure, nor would they be corrected: stop paying
  // for the registration once the first frames have all been such.
  const bool nothing_to_measure =
      decision_.frames_measured == 0 && frame_number >= kRefineAutoNoEvidenceFrame;
  if (decision_.frames_measured < kRefineAutoFrames && frame_number < kRefineAutoLastFrame &&
      !nothing_to_measure)
    return false;
  decision_.state = decision_.evidence > decision_.threshold ? AutoDecision::State::kOn
                                                             : AutoDecision::State::kOff;
  decision_.decided_at_frame = frame_number;
  if (decision_.state == AutoDecision::State::kOn && pose_check_.frames >= 0 &&
      pose_check_.ratio < pose_check_.threshold) {
    decision_.state = AutoDecision::State::kOff;
    decision_.basis = "held_out_poses";
    decision_.evidence = pose_check_.ratio;
    decision_.threshold = pose_check_.threshold;
    decision_.frames_measured = pose_check_.frames;
  }
  return true;
}

void RefineAutoDecider::SetPoseCheck(double ratio, double threshold, int frames) {
  pose_check_ = {ratio, threshold, frames};
}

void RefineAutoDecider::DecideOff(int frame_number) {
  if (!deciding()) return;
  decision_.state = AutoDecision::State::kOff;
  decision_.decided_at_frame = frame_number;
}

void BackgroundAutoDecider::Start(bool enabled, int warmup_frames, int expected_frames) {
  decision_ = AutoDecision();
  warmup_frames_ = warmup_frames;
  last_frames_ = expected_frames > 0 ? std::clamp(expected_frames / 3, kBackgroundAutoFrames,
                                                  kBackgroundAutoMaxFrames)
                                     : kBackgroundAutoMaxFrames;
  trusted_ = masked_ = 0;
  if (!enabled) return;
  decision_.state = AutoDecision::State::kDeciding;
  decision_.threshold = kBackgroundAutoThreshold;
  decision_.basis = "texels";
}

void BackgroundAutoDecider::DecideAcrossViews(double fraction, int frames) {
  if (!deciding()) return;
  decision_.basis = "across_views";
  decision_.threshold = kBackgroundAcrossViewsThreshold;
  decision_.evidence = fraction;
  decision_.frames_measured = frames;
  decision_.decided_at_frame = 0;
  decision_.state =
      fraction > decision_.threshold ? AutoDecision::State::kOn : AutoDecision::State::kOff;
}

bool BackgroundAutoDecider::AddFrame(int frame_number, long long observed, long long warming,
                                     long long masked) {
  if (!deciding() || frame_number < warmup_frames_) return false;
  trusted_ += std::max(0LL, observed - warming);
  masked_ += masked;
  ++decision_.frames_measured;
  if (trusted_ > 0) decision_.evidence = static_cast<double>(masked_) / trusted_;
  if (decision_.frames_measured < kBackgroundAutoFrames) return false;
  const bool on = decision_.evidence > decision_.threshold;
  if (!on && decision_.frames_measured < last_frames_) return false;
  decision_.state = on ? AutoDecision::State::kOn : AutoDecision::State::kOff;
  decision_.decided_at_frame = frame_number;
  return true;
}

}  // namespace fresco
