#include "pipeline/paint/paint_update.h"

namespace fresco {

void InitPaintedBuffer(const BaseBuffer& buffer, PaintedBuffer* painted) {
  // The paper initializes buffers white; alpha 0 marks them as never painted.
  painted->bgra.create(buffer.height, buffer.width, CV_8UC4);
  painted->bgra.setTo(cv::Scalar(255, 255, 255, 0));
  painted->quality.create(buffer.height, buffer.width, CV_32F);
  painted->quality.setTo(0);
  painted->painted_surface_texels = 0;
}

PaintUpdateStats PaintBuffer(const BaseBuffer& buffer, const WarpedBuffer& warped,
                             const cv::Mat& mask, UpdatePolicy policy, double quality_slack,
                             PaintedBuffer* painted) {
  PaintUpdateStats stats;
  const int w = buffer.width;
  const float keep = static_cast<float>(1.0 - quality_slack);
  for (int k = 0; k < buffer.NumTexels(); ++k) {
    const int idx = buffer.texel_index[k];
    const int i = idx % w, j = idx / w;
    if (!warped.valid.at<uint8_t>(j, i)) continue;
    if (!mask.empty() && mask.at<uint8_t>(j, i)) continue;
    const float q = warped.quality.at<float>(j, i);
    float& stored_q = painted->quality.at<float>(j, i);
    if (policy == UpdatePolicy::kQuality && q < stored_q * keep) {
      ++stats.rejected;
      continue;
    }
    cv::Vec4b& px = painted->bgra.at<cv::Vec4b>(j, i);
    if (px[3] == 0 && buffer.on_surface[k]) ++painted->painted_surface_texels;
    const cv::Vec3b& src = warped.bgr.at<cv::Vec3b>(j, i);
    px = cv::Vec4b(src[0], src[1], src[2], 255);
    stored_q = policy == UpdatePolicy::kQuality ? std::max(stored_q, q) : q;
    ++stats.written;
  }
  return stats;
}

}  // namespace fresco
