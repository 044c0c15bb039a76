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
  painted->mean_sum.release();
  painted->unmasked_sum.release();
  painted->shadow_bgra.release();
  painted->shadow_quality.release();
  painted->held_sum.release();
  painted->held_unmasked_sum.release();
  painted->sharp_sum.release();
  painted->held_sharp_sum.release();
  painted->texel_kind = cv::Mat::zeros(buffer.height, buffer.width, CV_8U);
  for (int k = 0; k < buffer.NumTexels(); ++k)
    painted->texel_kind.data[buffer.texel_index[k]] = buffer.on_surface[k] ? 2 : 1;
}

void AllocateSums(const TexelUpdateRule& rule, PaintedBuffer* painted) {
  if ((rule.policy == UpdatePolicy::kMean || rule.mean_too) && painted->mean_sum.empty())
    painted->mean_sum = cv::Mat::zeros(painted->bgra.size(), CV_32FC4);
  if (rule.unmasked_too && painted->unmasked_sum.empty())
    painted->unmasked_sum = cv::Mat::zeros(painted->bgra.size(), CV_32FC4);
  if (rule.mean_too && painted->shadow_bgra.empty()) {
    // The shadows start from what the texels hold (the frames before `auto` began deciding).
    painted->shadow_bgra = painted->bgra.clone();
    painted->shadow_quality = painted->quality.clone();
    painted->held_sum = cv::Mat::zeros(painted->bgra.size(), CV_32FC4);
    if (rule.sharp_too) {
      painted->sharp_sum = cv::Mat::zeros(painted->bgra.size(), CV_32FC4);
      painted->held_sharp_sum = cv::Mat::zeros(painted->bgra.size(), CV_32FC4);
    }
  }
  if (rule.unmasked_too && painted->held_unmasked_sum.empty())
    painted->held_unmasked_sum = cv::Mat::zeros(painted->bgra.size(), CV_32FC4);
}

namespace {

// The arrays one frame's update reads and writes, all in the rectangle's layout.
struct PaintArrays {
  const uint8_t* valid;
  const uint8_t* src;
  const float* quality;
  const uint8_t* skip;         // null: no mask
  const uint8_t* provisional;  // null: no sample is provisional
  uint8_t* dst;
  float* stored_quality;
  float* mean_sum;  // `update: mean` and `auto` (4 floats per texel), null otherwise
  float* unmasked_sum;  // `auto` with the background model on, null otherwise
  uint8_t* shadow_dst;  // `auto` deciding: PaintedBuffer's shadows, null otherwise
  float* shadow_quality;
  float* held_sum;
  float* held_unmasked_sum;
  float* sharp_sum;  // `auto` deciding: the sums of `sharp_mean`, null otherwise
  float* held_sharp_sum;

  PaintArrays(const WarpedBuffer& warped, const cv::Mat& mask, const cv::Mat& warming,
              PaintedBuffer* painted)
      : valid(warped.valid.data),
        src(warped.bgr.data),
        quality(warped.quality.ptr<float>()),
        skip(mask.empty() ? nullptr : mask.data),
        provisional(warming.empty() ? nullptr : warming.data),
        dst(painted->bgra.data),
        stored_quality(painted->quality.ptr<float>()),
        mean_sum(painted->mean_sum.empty() ? nullptr : painted->mean_sum.ptr<float>()),
        unmasked_sum(Floats(painted->unmasked_sum)),
        shadow_dst(painted->shadow_bgra.empty() ? nullptr : painted->shadow_bgra.data),
        shadow_quality(Floats(painted->shadow_quality)),
        held_sum(Floats(painted->held_sum)),
        held_unmasked_sum(Floats(painted->held_unmasked_sum)),
        sharp_sum(Floats(painted->sharp_sum)),
        held_sharp_sum(Floats(painted->held_sharp_sum)) {}
  static float* Floats(cv::Mat& m) { return m.empty() ? nullptr : m.ptr<float>(); }
};

// One texel by the quality rule into `dst` and `stored_quality` (the texels or, for `auto`
// deciding, their shadows).
[[gnu::always_inline]] inline void QualityTexel(const PaintArrays& a, int idx, bool on_surface,
                                                const TexelUpdateRule& rule, uint8_t* dst,
                                                float* stored_quality, PaintUpdateStats* stats) {
  const bool provisional = a.provisional && a.provisional[idx];
  if (a.valid[idx] && !(a.skip && a.skip[idx])) {
    const float stored = stored_quality[idx];
    uint8_t* texel = dst + 4 * static_cast<size_t>(idx);
    const uint8_t* sample = a.src + 3 * static_cast<size_t>(idx);
    const float quality = RuleQuality(rule, a.quality[idx]);
    if (stored >= 0.0f) {
      UpdateTexel(rule, sample, quality, on_surface, texel, stored_quality + idx, stats);
    } else {
      // A provisional stored sample: against a trusted sample it counts as nothing; against
      // another provisional one, by its quality.
      float compared_with = provisional ? -stored : 0.0f;
      const int written_before = stats->written;
      UpdateTexel(rule, sample, quality, on_surface, texel, &compared_with, stats);
      if (stats->written > written_before) stored_quality[idx] = compared_with;
    }
  }
  // Negated: the sign marks the stored sample provisional, the magnitude keeps its quality.
  if (provisional) stored_quality[idx] = -std::abs(stored_quality[idx]);
}

// One texel (rectangle index `idx`).
[[gnu::always_inline]] inline void PaintTexel(const PaintArrays& a, int idx, bool on_surface,
                                              const TexelUpdateRule& rule,
                                              PaintUpdateStats* stats) {
  const bool take = a.valid[idx] && !(a.skip && a.skip[idx]);
  const bool provisional = a.provisional && a.provisional[idx];
  const float quality = RuleQuality(rule, a.quality[idx]);
  if (a.mean_sum && !rule.mean_too) {
    if (take)
      MeanTexel(a.src + 3 * static_cast<size_t>(idx),
                rule.sharp ? SharpWeight(a.quality[idx]) : quality, quality, provisional,
                on_surface, a.dst + 4 * static_cast<size_t>(idx), a.stored_quality + idx,
                a.mean_sum + 4 * static_cast<size_t>(idx), stats);
    return;
  }
  if (rule.mean_too) {  // `auto` deciding: the means beside the sharpest
    const uint8_t* sample = a.src + 3 * static_cast<size_t>(idx);
    const size_t at = 4 * static_cast<size_t>(idx);
    if (take) {
      AddToMean(sample, quality, provisional, a.mean_sum + at,
                a.held_sum ? a.held_sum + at : nullptr, rule.held_out);
      if (a.sharp_sum)
        AddToMean(sample, SharpWeight(a.quality[idx]), provisional, a.sharp_sum + at,
                  a.held_sharp_sum + at, rule.held_out);
    }
    if (a.unmasked_sum && a.valid[idx])  // without the model: no sample is provisional
      AddToMean(sample, quality, false, a.unmasked_sum + at,
                a.held_unmasked_sum ? a.held_unmasked_sum + at : nullptr, rule.held_out);
    PaintUpdateStats ignored;
    if (!rule.held_out && a.shadow_dst)
      QualityTexel(a, idx, on_surface, rule, a.shadow_dst, a.shadow_quality, &ignored);
  }
  QualityTexel(a, idx, on_surface, rule, a.dst, a.stored_quality, stats);
}

// Rows [y0, y1) of the warped box `box`, left to right: every array is read and written in
// the rectangle's order, one stream each, which the hardware prefetches (a tile at a time
// they were 16 streams per array). Texels outside the buffer and those not seen this frame
// have `valid` and `warming` 0 and are left alone, as the texel order would leave them; so are
// the rectangle's texels that are not the buffer's (refinement may warp `valid` onto them).
PaintUpdateStats PaintRows(const WarpedBuffer& warped, const cv::Mat& mask, const cv::Mat& warming,
                           const TexelUpdateRule& rule, const cv::Rect& box, int y0, int y1,
                           PaintedBuffer* painted) {
  PaintUpdateStats stats;
  const PaintArrays a(warped, mask, warming, painted);
  const uint8_t* kind = painted->texel_kind.data;
  const int width = warped.valid.cols;
  for (int y = y0; y < y1; ++y) {
    const int row = y * width;
    for (int idx = row + box.x; idx < row + box.x + box.width; ++idx) {
      if (kind[idx] == 0 || (!a.valid[idx] && !(a.provisional && a.provisional[idx]))) continue;
      PaintTexel(a, idx, kind[idx] == 2, rule, &stats);
    }
  }
  return stats;
}

// Texels [begin, end) of one chunk.
PaintUpdateStats PaintTexels(const BaseBuffer& buffer, const WarpedBuffer& warped,
                             const cv::Mat& mask, const cv::Mat& warming,
                             const TexelUpdateRule& rule, int begin, int end,
                             PaintedBuffer* painted) {
  PaintUpdateStats stats;
  const PaintArrays a(warped, mask, warming, painted);
  for (int k = begin; k < end; ++k)
    PaintTexel(a, buffer.texel_index[k], buffer.on_surface[k] != 0, rule, &stats);
  return stats;
}

}  // namespace

PaintUpdateStats PaintBuffer(const BaseBuffer& buffer, const WarpedBuffer& warped,
                             const cv::Mat& mask, const PipelineOptions& options,
                             PaintedBuffer* painted, const cv::Mat& warming, bool held_out) {
  TexelUpdateRule rule = TexelUpdateRule::From(options);
  rule.held_out = held_out && rule.mean_too;
  AllocateSums(rule, painted);
  PaintUpdateStats stats;
  if (buffer.chunks.empty()) {  // a hand-made buffer: all texels, no culling
    stats = PaintTexels(buffer, warped, mask, warming, rule, 0, buffer.NumTexels(), painted);
    painted->painted_surface_texels += stats.newly_painted;
    return stats;
  }
  if (painted->texel_kind.size() == painted->bgra.size() && warped.valid.isContinuous() &&
      painted->bgra.isContinuous()) {
    // Row by row over the box the warp wrote, in bands of rows in parallel (disjoint texels),
    // reduced in band order (deterministic).
    const cv::Rect box = warped.valid_box & cv::Rect(0, 0, buffer.width, buffer.height);
    constexpr int kBandRows = 16;
    const int bands = (box.height + kBandRows - 1) / kBandRows;
    std::vector<PaintUpdateStats> per_band(std::max(bands, 0));
    cv::parallel_for_(
        cv::Range(0, std::max(bands, 0)),
        [&](const cv::Range& range) {
          for (int i = range.start; i < range.end; ++i) {
            const int y0 = box.y + i * kBandRows;
            per_band[i] = PaintRows(warped, mask, warming, rule, box, y0,
                                    std::min(y0 + kBandRows, box.br().y), painted);
          }
        },
        std::max(1, bands));
    for (const PaintUpdateStats& s : per_band) stats.Add(s);
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
