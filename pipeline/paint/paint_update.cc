#include "pipeline/paint/paint_update.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <vector>

#include <opencv2/core/utility.hpp>

namespace fresco {

void InitPaintedBuffer(const BaseBuffer& buffer, PaintedBuffer* painted) {
  // The paper initializes buffers white; alpha 0 marks them as never painted.
  painted->bgra.create(buffer.height, buffer.width, CV_8UC4);
  painted->bgra.setTo(cv::Scalar(255, 255, 255, 0));
  painted->quality.create(buffer.height, buffer.width, CV_32F);
  painted->quality.setTo(0);
  painted->painted_surface_texels = 0;
}

namespace {

// Texels [begin, end) of one chunk; `newly_painted`: surface texels painted the first time.
PaintUpdateStats PaintTexels(const BaseBuffer& buffer, const WarpedBuffer& warped,
                             const cv::Mat& mask, const PipelineOptions& options, int begin,
                             int end, PaintedBuffer* painted, int* newly_painted) {
  PaintUpdateStats stats;
  const UpdatePolicy policy = options.update;
  const float keep = static_cast<float>(1.0 - options.quality_slack);
  // Fixed point: the new sample's weight out of 256 (256 = replace).
  const int weight = std::clamp(static_cast<int>(std::lround(256 * options.update_weight)), 1, 256);
  const uint8_t* valid = warped.valid.data;
  const cv::Vec3b* src = warped.bgr.ptr<cv::Vec3b>();
  const float* quality = warped.quality.ptr<float>();
  const uint8_t* skip = mask.empty() ? nullptr : mask.data;
  cv::Vec4b* dst = painted->bgra.ptr<cv::Vec4b>();
  float* stored_quality = painted->quality.ptr<float>();
  for (int k = begin; k < end; ++k) {
    const int idx = buffer.texel_index[k];
    if (!valid[idx] || (skip && skip[idx])) continue;
    cv::Vec4b& px = dst[idx];
    if (px[3] != 0) {  // compare with what the buffer holds (BT.601 luma, integer weights)
      const int new_grey = (29 * src[idx][0] + 150 * src[idx][1] + 77 * src[idx][2]) >> 8;
      const int old_grey = (29 * px[0] + 150 * px[1] + 77 * px[2]) >> 8;
      stats.abs_grey_difference_sum += std::abs(new_grey - old_grey);
      ++stats.compared;
    }
    const float q = quality[idx];
    float& stored_q = stored_quality[idx];
    if (policy == UpdatePolicy::kQuality && q < stored_q * keep) {
      ++stats.rejected;
      continue;
    }
    if (px[3] == 0 && buffer.on_surface[k]) ++*newly_painted;
    if (px[3] == 0 || weight == 256) {
      px = cv::Vec4b(src[idx][0], src[idx][1], src[idx][2], 255);
    } else {
      for (int c = 0; c < 3; ++c) px[c] = static_cast<uint8_t>((px[c] * (256 - weight) + src[idx][c] * weight + 128) >> 8);
    }
    stored_q = policy == UpdatePolicy::kQuality ? std::max(stored_q, q) : q;
    ++stats.written;
  }
  return stats;
}

}  // namespace

PaintUpdateStats PaintBuffer(const BaseBuffer& buffer, const WarpedBuffer& warped,
                             const cv::Mat& mask, const PipelineOptions& options,
                             PaintedBuffer* painted) {
  PaintUpdateStats stats;
  int newly_painted = 0;
  if (buffer.chunks.empty()) {  // a hand-made buffer: all texels, no culling
    stats = PaintTexels(buffer, warped, mask, options, 0, buffer.NumTexels(), painted,
                        &newly_painted);
    painted->painted_surface_texels += newly_painted;
    return stats;
  }
  // Chunks write disjoint texels: in parallel, only those that may hold valid texels,
  // reduced in chunk order (deterministic).
  const int num_chunks = static_cast<int>(buffer.chunks.size());
  std::vector<PaintUpdateStats> per_chunk(num_chunks);
  std::vector<int> newly(num_chunks, 0);
  cv::parallel_for_(
      cv::Range(0, num_chunks),
      [&](const cv::Range& range) {
        for (int c = range.start; c < range.end; ++c) {
          const BaseBuffer::Chunk& chunk = buffer.chunks[c];
          if (!warped.MayBeValid(chunk)) continue;
          per_chunk[c] = PaintTexels(buffer, warped, mask, options, chunk.begin, chunk.end,
                                     painted, &newly[c]);
        }
      },
      std::max(1, std::min(num_chunks, 16 * cv::getNumThreads())));
  for (int c = 0; c < num_chunks; ++c) {
    stats.written += per_chunk[c].written;
    stats.rejected += per_chunk[c].rejected;
    stats.compared += per_chunk[c].compared;
    stats.abs_grey_difference_sum += per_chunk[c].abs_grey_difference_sum;
    newly_painted += newly[c];
  }
  painted->painted_surface_texels += newly_painted;
  return stats;
}

}  // namespace fresco
