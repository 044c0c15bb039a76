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

// Texels [begin, end) of one chunk.
PaintUpdateStats PaintTexels(const BaseBuffer& buffer, const WarpedBuffer& warped,
                             const cv::Mat& mask, const cv::Mat& warming,
                             const TexelUpdateRule& rule, int begin, int end,
                             PaintedBuffer* painted) {
  PaintUpdateStats stats;
  const uint8_t* valid = warped.valid.data;
  const uint8_t* src = warped.bgr.data;
  const float* quality = warped.quality.ptr<float>();
  const uint8_t* skip = mask.empty() ? nullptr : mask.data;
  const uint8_t* provisional_sample = warming.empty() ? nullptr : warming.data;
  uint8_t* dst = painted->bgra.data;
  float* stored_quality = painted->quality.ptr<float>();
  for (int k = begin; k < end; ++k) {
    const int idx = buffer.texel_index[k];
    const bool provisional = provisional_sample && provisional_sample[idx];
    if (valid[idx] && !(skip && skip[idx])) {
      const float stored = stored_quality[idx];
      uint8_t* texel = dst + 4 * static_cast<size_t>(idx);
      if (stored >= 0.0f) {
        UpdateTexel(rule, src + 3 * static_cast<size_t>(idx), quality[idx], buffer.on_surface[k],
                    texel, stored_quality + idx, &stats);
      } else {
        // A provisional stored sample: against a trusted sample it counts as nothing; against
        // another provisional one, by its quality.
        float compared_with = provisional ? -stored : 0.0f;
        const int written_before = stats.written;
        UpdateTexel(rule, src + 3 * static_cast<size_t>(idx), quality[idx], buffer.on_surface[k],
                    texel, &compared_with, &stats);
        if (stats.written > written_before) stored_quality[idx] = compared_with;
      }
    }
    // Negated: the sign marks the stored sample provisional, the magnitude keeps its quality.
    if (provisional) stored_quality[idx] = -std::abs(stored_quality[idx]);
  }
  return stats;
}

}  // namespace

PaintUpdateStats PaintBuffer(const BaseBuffer& buffer, const WarpedBuffer& warped,
                             const cv::Mat& mask, const PipelineOptions& options,
                             PaintedBuffer* painted, const cv::Mat& warming) {
  const TexelUpdateRule rule = TexelUpdateRule::From(options);
  PaintUpdateStats stats;
  if (buffer.chunks.empty()) {  // a hand-made buffer: all texels, no culling
    stats = PaintTexels(buffer, warped, mask, warming, rule, 0, buffer.NumTexels(), painted);
    painted->painted_surface_texels += stats.newly_painted;
    return stats;
  }
  // Chunks write disjoint texels: in parallel, only those that may hold valid texels,
  // reduced in chunk order (deterministic).
  const int num_chunks = static_cast<int>(buffer.chunks.size());
  std::vector<PaintUpdateStats> per_chunk(num_chunks);
  cv::parallel_for_(
      cv::Range(0, num_chunks),
      [&](const cv::Range& range) {
        for (int c = range.start; c < range.end; ++c) {
          const BaseBuffer::Chunk& chunk = buffer.chunks[c];
          if (!warped.MayBeValid(chunk)) continue;
          per_chunk[c] =
              PaintTexels(buffer, warped, mask, warming, rule, chunk.begin, chunk.end, painted);
        }
      },
      std::max(1, std::min(num_chunks, 16 * cv::getNumThreads())));
  for (const PaintUpdateStats& s : per_chunk) stats.Add(s);
  painted->painted_surface_texels += stats.newly_painted;
  return stats;
}

}  // namespace fresco
