// `update: auto`: the sharpest view or the mean of every view, decided on the frames the run
// held back (PaintSession::DecideUpdate, paint_session.h).
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>

#include "pipeline/paint/paint_session.h"
#include "pipeline/paint/rephotography.h"
#include "pipeline/render/renderer.h"

namespace fresco {

namespace {

// The texels as `update: mean` would hold them with `sums`: their mean where they have a
// weight, what the texel holds elsewhere.
cv::Mat MeanTexels(const PaintedBuffer& painted, const cv::Mat& sums) {
  cv::Mat bgra = painted.bgra.clone();
  if (sums.empty()) return bgra;
  for (int y = 0; y < bgra.rows; ++y) {
    const cv::Vec4f* sum = sums.ptr<cv::Vec4f>(y);
    cv::Vec4b* texel = bgra.ptr<cv::Vec4b>(y);
    for (int x = 0; x < bgra.cols; ++x) {
      if (sum[x][3] <= 0) continue;
      for (int c = 0; c < 3; ++c) texel[x][c] = cv::saturate_cast<uint8_t>(sum[x][c] / sum[x][3]);
      texel[x][3] = 255;
    }
  }
  return bgra;
}

}  // namespace

void PaintSession::DecideUpdate(const std::vector<HeldBackFrame>& frames) {
  if (!DecidingUpdate()) return;
  // The candidates: what the texels hold (the sharpest view), the mean of every view and,
  // with the background model on where `auto` turned it on, that mean without the model.
  const bool without_model = requested_background_ == BackgroundMode::kAuto &&
                             options_.background.mode != BackgroundMode::kOff;
  std::vector<std::vector<cv::Mat>> texels(without_model ? 3 : 2);
  for (const PaintedBuffer& painted : painted_) {
    texels[0].push_back(painted.bgra);
    texels[1].push_back(MeanTexels(painted, painted.mean_sum));
    if (without_model) texels[2].push_back(MeanTexels(painted, painted.unmasked_sum));
  }
  std::vector<Scene> scenes;
  for (const std::vector<cv::Mat>& candidate : texels) {
    std::vector<cv::Mat> shown;
    for (const cv::Mat& bgra : candidate) shown.push_back(AtMeanExposure(bgra));
    scenes.push_back(PaintedScene(shown));
  }
  std::map<const Camera*, std::unique_ptr<Renderer>> renderers;
  std::vector<double> psnr_sum(scenes.size(), 0.0);
  int measured = 0;
  for (const HeldBackFrame& frame : frames) {
    auto& renderer = renderers[frame.camera];
    if (!renderer) renderer = std::make_unique<Renderer>(*frame.camera, RenderOptions());
    std::vector<double> psnr;
    for (const Scene& scene : scenes) {
      const RephotoScore s = ScoreRephoto(*renderer, scene, frame.cam_from_world, frame.bgr);
      if (s.pixels > 0 && std::isfinite(s.psnr_db)) psnr.push_back(s.psnr_db);
    }
    if (psnr.size() != scenes.size()) continue;  // no painted surface in view
    for (size_t c = 0; c < psnr.size(); ++c) psnr_sum[c] += psnr[c];
    ++measured;
  }
  // The best candidate by mean PSNR; the sharpest view where none was measured.
  size_t best = 0;
  for (size_t c = 1; c < scenes.size() && measured > 0; ++c)
    if (psnr_sum[c] > psnr_sum[best]) best = c;
  const double best_mean = *std::max_element(psnr_sum.begin() + 1, psnr_sum.end());
  update_auto_.frames_measured = measured;
  update_auto_.decided_at_frame = frames_seen_;
  update_auto_.evidence = measured > 0 ? (best_mean - psnr_sum[0]) / measured
                                       : std::numeric_limits<double>::quiet_NaN();
  const bool mean = best > 0;
  update_auto_.state = mean ? AutoDecision::State::kOn : AutoDecision::State::kOff;
  options_.update = mean ? UpdatePolicy::kMean : UpdatePolicy::kQuality;
  if (best == 2) {  // the model off from now on, its sums the mean's
    background_auto_.OffByFramesHeldBack(frames_seen_, (psnr_sum[2] - psnr_sum[1]) / measured,
                                         measured);
    options_.background.mode = BackgroundMode::kOff;
    background_.clear();
    background_frame_.clear();
  }
  for (size_t b = 0; b < painted_.size(); ++b) {
    PaintedBuffer& painted = painted_[b];
    if (mean) {
      painted.bgra = texels[best][b];
      if (best == 2) painted.mean_sum = painted.unmasked_sum;
      cv::absdiff(painted.quality, 0, painted.quality);  // none provisional: every view counts
    } else {
      painted.mean_sum.release();
    }
    painted.unmasked_sum.release();
  }
}

}  // namespace fresco
