// Plain structs every pipeline stage fills for each frame: wall time, named metrics and,
// when asked, debug images. The CLI (metrics.json, stages/) and the GUI's stage panels both
// read these; the pipeline never calls either.
//
// Figures that other code reads back as data (the time-offset estimation, the app's
// misalignment and refinement plots) are typed fields (PaintFigures, RefineFigures): a
// rename does not compile, where a string key would silently read NaN. The stage's
// `metrics` map shows them too (panels, metrics.json), made from the typed struct.
#pragma once

#include <limits>
#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace fresco {

struct StageReport {
  std::string name;  // "depth", "warp", "paint", ...
  double wall_ms = 0.0;
  std::map<std::string, double> metrics;     // e.g. {"texels_visible", 12345}
  std::map<std::string, cv::Mat> images;     // debug images (BGR or gray), only when asked
  std::map<std::string, std::string> notes;  // words: chosen model, why no correction, ...
};

// The paint stage's figures read back as data.
struct PaintFigures {
  // Mean |grey difference| between the frame and what the buffers held, where both exist
  // (grey levels, 0..255): a cheap misalignment signal (pose error, time offset, exposure
  // change, movers). NaN when nothing was compared.
  double difference_to_buffer = std::numeric_limits<double>::quiet_NaN();

  // Shows the figures in the paint stage's metrics (the names are the fields').
  void PutInto(StageReport* paint) const {
    paint->metrics["difference_to_buffer"] = difference_to_buffer;
  }
};

// The refine stage's figures read back as data (when the stage ran).
struct RefineFigures {
  // RMS residual over all inliers, texels: with no correction (before) and with the chosen
  // corrections (after). NaN when nothing was matched.
  double residual_before_px = std::numeric_limits<double>::quiet_NaN();
  double residual_after_px = std::numeric_limits<double>::quiet_NaN();

  void PutInto(StageReport* refine) const {
    refine->metrics["residual_before_px"] = residual_before_px;
    refine->metrics["residual_after_px"] = residual_after_px;
  }
};

// The background stage's figures read back as data (when the stage ran): per-stream
// statistics (paint_run.h) sum them over a stream's frames.
struct BackgroundFigures {
  long long texels_observed = 0;  // texels sampled this frame in the buffers seen
  long long texels_masked = 0;    // ... masked as foreground (after cleaning)

  void PutInto(StageReport* background) const {
    background->metrics["texels_observed"] = static_cast<double>(texels_observed);
    background->metrics["texels_masked"] = static_cast<double>(texels_masked);
    background->metrics["masked_fraction"] =
        texels_observed > 0 ? static_cast<double>(texels_masked) / texels_observed : 0.0;
  }
};

// What an `auto` mode (refine.mode, background.mode) decided and on what evidence
// (auto_modes.h): the figure measured on the capture itself, the threshold it was compared
// with and the frames it was measured over. Deciding until the decision point, then fixed
// for the rest of the session.
struct AutoDecision {
  enum class State { kNotAuto, kDeciding, kOn, kOff };
  State state = State::kNotAuto;
  double evidence = std::numeric_limits<double>::quiet_NaN();
  double threshold = std::numeric_limits<double>::quiet_NaN();
  int frames_measured = 0;
  int decided_at_frame = -1;  // the session's frame number where it was decided; -1: not yet
  // What the evidence is, when the mode has more than one kind: background "across_views"
  // (decided before painting from the movers found across views) or "texels" (the model's own
  // verdicts while painting); "" otherwise.
  std::string basis;

  bool is_auto() const { return state != State::kNotAuto; }
  // "deciding" | "on" | "off" ("" when the mode is not auto).
  const char* StateName() const {
    switch (state) {
      case State::kDeciding:
        return "deciding";
      case State::kOn:
        return "on";
      case State::kOff:
        return "off";
      default:
        return "";
    }
  }
  // One line for people: "on: 1.84 > 0.6 over 6 frames (decided at frame 7)" (the figure's
  // meaning is the mode's: AutoDecisions); "" when not auto.
  std::string Describe() const;
  // Shows it in a stage's metrics (auto_decision: 0 deciding, 1 on, -1 off; auto_evidence,
  // auto_threshold) and notes (auto: Describe()).
  void PutInto(StageReport* stage) const {
    if (!is_auto()) return;
    stage->metrics["auto_decision"] =
        state == State::kOn ? 1.0 : (state == State::kOff ? -1.0 : 0.0);
    stage->metrics["auto_evidence"] = evidence;
    stage->metrics["auto_threshold"] = threshold;
    stage->notes["auto"] = Describe();
  }
};

struct AutoDecisions {
  // evidence: median misalignment of the first frames, texels; or (basis "held_out_poses",
  // decided off before painting) how many times better frames left out of the joint pose
  // adjustment agree with the corrected frames (joint_pose_adjustment.h)
  AutoDecision refine;
  // evidence: the share of the pixels masked across views (basis "across_views"), or the
  // foreground fraction of the warmed-up texels ("texels")
  AutoDecision background;
  // update `auto`: on = `mean`, off = `quality`; evidence: how many dB more PSNR the
  // mean scores than the sharpest view at the frames held out (basis "held_out")
  AutoDecision update;
};

struct FrameReport {
  int frame = -1;
  std::string name;
  bool painted = false;        // false when skipped (no pose, update_every, ...)
  std::string skipped_reason;  // why not painted
  std::vector<StageReport> stages;
  double total_ms = 0.0;
  PaintFigures paint;            // when painted
  RefineFigures refine;          // when the refine stage ran (Stage("refine") != nullptr)
  BackgroundFigures background;  // when the background stage ran (else zeros)
  AutoDecisions decisions;       // the `auto` modes' state after this frame

  StageReport* Stage(const std::string& name) {
    for (auto& s : stages)
      if (s.name == name) return &s;
    return nullptr;
  }
  const StageReport* Stage(const std::string& name) const {
    for (const auto& s : stages)
      if (s.name == name) return &s;
    return nullptr;
  }
};

}  // namespace fresco
