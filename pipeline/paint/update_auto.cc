// `update: auto`: the sharpest view or the mean of every view, decided on the frames the run
// held back (PaintSession::DecideUpdate, paint_session.h).
#include <cmath>
#include <limits>
#include <map>
#include <memory>

#include "pipeline/paint/paint_session.h"
#include "pipeline/paint/rephotography.h"
#include "pipeline/render/renderer.h"

namespace fresco {

namespace {

// The texels as `update: mean` would hold them: the mean of the sums where they have a
// weight, what the texel holds elsewhere.
cv::Mat MeanTexels(const PaintedBuffer& painted) {
  cv::Mat bgra = painted.bgra.clone();
  if (painted.mean_sum.empty()) return bgra;
  for (int y = 0; y < bgra.rows; ++y) {
    const cv::Vec4f* sum = painted.mean_sum.ptr<cv::Vec4f>(y);
    cv::Vec4b* texel = bgra.ptr<cv::Vec4b>(y);
    for (int x = 0; x < bgra.cols; ++x) {
      if (sum[x][3] <= 0 || texel[x][3] == 0) continue;
      for (int c = 0; c < 3; ++c) texel[x][c] = cv::saturate_cast<uint8_t>(sum[x][c] / sum[x][3]);
    }
  }
  return bgra;
}

}  // namespace

void PaintSession::DecideUpdate(const std::vector<HeldBackFrame>& frames) {
  if (!DecidingUpdate()) return;
  std::vector<cv::Mat> sharpest, mean_of_all;
  for (const PaintedBuffer& painted : painted_) {
    sharpest.push_back(AtMeanExposure(painted.bgra));
    mean_of_all.push_back(MeanTexels(painted));
  }
  std::vector<cv::Mat> mean_shown;
  for (const cv::Mat& bgra : mean_of_all) mean_shown.push_back(AtMeanExposure(bgra));
  const Scene by_sharpest = PaintedScene(sharpest), by_mean = PaintedScene(mean_shown);
  std::map<const Camera*, std::unique_ptr<Renderer>> renderers;
  double gain_sum = 0;
  int measured = 0;
  for (const HeldBackFrame& frame : frames) {
    auto& renderer = renderers[frame.camera];
    if (!renderer) renderer = std::make_unique<Renderer>(*frame.camera, RenderOptions());
    const RephotoScore a = ScoreRephoto(*renderer, by_sharpest, frame.cam_from_world, frame.bgr);
    const RephotoScore b = ScoreRephoto(*renderer, by_mean, frame.cam_from_world, frame.bgr);
    if (a.pixels == 0 || b.pixels == 0 || !std::isfinite(a.psnr_db) || !std::isfinite(b.psnr_db))
      continue;
    gain_sum += b.psnr_db - a.psnr_db;
    ++measured;
  }
  update_auto_.frames_measured = measured;
  update_auto_.decided_at_frame = frames_seen_;
  update_auto_.evidence =
      measured > 0 ? gain_sum / measured : std::numeric_limits<double>::quiet_NaN();
  const bool mean = measured > 0 && update_auto_.evidence > update_auto_.threshold;
  update_auto_.state = mean ? AutoDecision::State::kOn : AutoDecision::State::kOff;
  options_.update = mean ? UpdatePolicy::kMean : UpdatePolicy::kQuality;
  for (size_t b = 0; b < painted_.size(); ++b) {
    PaintedBuffer& painted = painted_[b];
    if (mean) {
      painted.bgra = mean_of_all[b];
      cv::absdiff(painted.quality, 0, painted.quality);  // none provisional: every view counts
    } else {
      painted.mean_sum.release();
    }
  }
}

}  // namespace fresco
