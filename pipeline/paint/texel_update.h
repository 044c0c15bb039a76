// How one new sample updates one stored texel (the paper's §4 policy, or quality-aware, with
// an optional running average), shared by the paint stage and by the warp when it paints
// directly (frame_warp.h): one rule, one place. `update: mean` (MeanTexel) keeps sums beside
// the texels and runs in the paint stage only.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include <opencv2/core.hpp>

#include "pipeline/core/project.h"

namespace fresco {

struct PaintedBuffer {
  cv::Mat bgra;                    // CV_8UC4, alpha 255 where painted, 0 where never painted
  cv::Mat quality;                 // CV_32F, quality of the stored sample (pixels per texel)
  int painted_surface_texels = 0;  // on-surface texels painted at least once
  // CV_8U, per texel of the rectangle: 0 not one of the buffer's texels, 1 in the gutter, 2 on
  // the surface (BaseBuffer::texel_index and on_surface in the rectangle's layout), for
  // updates that walk the rectangle row by row (InitPaintedBuffer).
  cv::Mat texel_kind;
  // `update: mean`: per texel the sum of the samples taken, each weighted by its quality
  // (CV_32FC4: B, G, R and the weights' sum; made on the first frame painted, empty otherwise).
  cv::Mat mean_sum;
  // `update: auto` while deciding with the background model on: the same sums over every
  // sample, the model's foreground too (what the mean would be without the model).
  cv::Mat unmasked_sum;
  // `update: auto` while deciding, without the frames held out of the decision (painted as
  // every other frame into the stores above): the texels and qualities `quality` would
  // hold, and the held-out frames' own part of mean_sum and unmasked_sum (subtracted).
  cv::Mat shadow_bgra, shadow_quality, held_sum, held_unmasked_sum;
  // `update: auto` while deciding: the sums of `sharp_mean` (each sample weighted by the
  // pixels its view has on the texel, SharpWeight) beside mean_sum, and the held-out frames'
  // part of them.
  cv::Mat sharp_sum, held_sharp_sum;
};

struct PaintUpdateStats {
  int written = 0;   // texels written this frame
  int rejected = 0;  // visible but kept the stored, sharper sample
  // Misalignment signal: over texels that were already painted and are seen again, the sum
  // of |grey(new sample) - grey(stored)| (0..255 each) and how many there were.
  long long abs_grey_difference_sum = 0;  // an integer: no floating-point chain per texel
  int compared = 0;
  int newly_painted = 0;  // on-surface texels painted for the first time

  void Add(const PaintUpdateStats& o) {
    written += o.written, rejected += o.rejected, compared += o.compared;
    abs_grey_difference_sum += o.abs_grey_difference_sum, newly_painted += o.newly_painted;
  }
};

// The pipeline's update options resolved for the per-texel loop.
struct TexelUpdateRule {
  UpdatePolicy policy = UpdatePolicy::kQuality;
  float keep = 0.8f;  // kQuality: a sample at least this fraction as sharp overwrites
  int weight = 256;   // the new sample's weight out of 256 (256 = replace)
  // `update: auto` while deciding: kQuality into the texels, kMean into the sums too.
  bool mean_too = false;
  bool unmasked_too = false;  // ... and with the background model on, PaintedBuffer::unmasked_sum
  bool held_out = false;      // ... and this frame is held out of the decision (the shadows)
  // `sharp_mean` (policy kMean with this set): the sums weigh each sample by SharpWeight.
  bool sharp = false;
  // `auto` deciding: PaintedBuffer::sharp_sum too.
  bool sharp_too = false;
  // The qualities the rules read are pixels per texel, counted up to 1 (RuleQuality); false
  // where view selection scored them (its scores are compared as they are).
  bool cap_quality = true;

  static TexelUpdateRule From(const PipelineOptions& options) {
    TexelUpdateRule rule;
    rule.policy = options.update;
    if (options.update == UpdatePolicy::kAuto) {
      rule.policy = UpdatePolicy::kQuality;
      rule.mean_too = true;
      rule.sharp_too = options.layers.count == 0;  // layers keep the sharpest or the mean
      rule.unmasked_too = options.background.mode != BackgroundMode::kOff;
    }
    if (options.update == UpdatePolicy::kSharpMean) {
      rule.policy = UpdatePolicy::kMean;
      rule.sharp = true;
    }
    rule.cap_quality = !options.select.enabled;
    rule.keep = static_cast<float>(1.0 - options.quality_slack);
    rule.weight = std::clamp(static_cast<int>(std::lround(256 * options.update_weight)), 1, 256);
    return rule;
  }
};

// The sums `rule` paints into (PaintedBuffer::mean_sum and, for `update: auto` deciding, the
// shadows and held-out parts), made where missing (paint_update.cc).
void AllocateSums(const TexelUpdateRule& rule, PaintedBuffer* painted);

// A view's pixels per texel as the update rules weigh it (`quality`, `mean`): up to one pixel
// per texel (a texel seen by a pixel or more counts as seen sharp); view selection's scores
// as they are.
inline float RuleQuality(const TexelUpdateRule& rule, float pixels_per_texel) {
  return rule.cap_quality ? std::min(1.0f, pixels_per_texel) : pixels_per_texel;
}

// `sharp_mean`'s weight of a sample: the pixels its view has on the texel (pixels per texel
// squared, not capped), so near and head-on views count more where every view is averaged.
inline float SharpWeight(float pixels_per_texel) { return pixels_per_texel * pixels_per_texel; }

// The misalignment signal: a sample against what a painted texel holds (BT.601 luma, integer
// weights), into `stats`.
inline void CompareWithStored(const uint8_t* sample, const uint8_t* texel,
                              PaintUpdateStats* stats) {
  if (texel[3] == 0) return;
  const int new_grey = (29 * sample[0] + 150 * sample[1] + 77 * sample[2]) >> 8;
  const int old_grey = (29 * texel[0] + 150 * texel[1] + 77 * texel[2]) >> 8;
  stats->abs_grey_difference_sum += std::abs(new_grey - old_grey);
  ++stats->compared;
}

// `sample`: BGR; `quality`: its pixels per texel; `texel`: the stored BGRA; `stored_quality`:
// the stored sample's quality. Counts into `stats`.
inline void UpdateTexel(const TexelUpdateRule& rule, const uint8_t* sample, float quality,
                        bool on_surface, uint8_t* texel, float* stored_quality,
                        PaintUpdateStats* stats) {
  CompareWithStored(sample, texel, stats);
  if (rule.policy == UpdatePolicy::kQuality && quality < *stored_quality * rule.keep) {
    ++stats->rejected;
    return;
  }
  if (texel[3] == 0 && on_surface) ++stats->newly_painted;
  if (texel[3] == 0 || rule.weight == 256) {
    texel[0] = sample[0], texel[1] = sample[1], texel[2] = sample[2], texel[3] = 255;
  } else {
    for (int c = 0; c < 3; ++c)
      texel[c] = static_cast<uint8_t>(
          (texel[c] * (256 - rule.weight) + sample[c] * rule.weight + 128) >> 8);
  }
  *stored_quality =
      rule.policy == UpdatePolicy::kQuality ? std::max(*stored_quality, quality) : quality;
  ++stats->written;
}

// Adds the sample, weighted by `quality` (RuleQuality, or SharpWeight), to a texel's sums (`sum`:
// B, G, R, weight). A provisional sample (the background model still learning the texel: it may
// show a mover) counts only until the texel's first trusted one, which replaces them: the weight of
// sums of provisional samples only is kept negative. `held` (optional): the part of `sum` taken
// from frames held out of `update: auto`'s decision; it follows `sum`'s replacements and
// takes the sample too when `held_out`.
inline void AddToMean(const uint8_t* sample, float quality, bool provisional, float* sum,
                      float* held = nullptr, bool held_out = false) {
  if (provisional && sum[3] > 0) return;  // trusted samples are in: it counts as nothing
  if (!provisional && sum[3] < 0) {       // the first trusted one: the provisional ones go
    std::fill(sum, sum + 4, 0.0f);
    if (held) std::fill(held, held + 4, 0.0f);
  }
  const float w = std::max(quality, 1e-3f);
  for (float* s : {sum, held_out ? held : nullptr}) {
    if (!s) continue;
    for (int c = 0; c < 3; ++c) s[c] += w * sample[c];
    s[3] += provisional ? -w : w;
  }
}

// The mean a texel's sums (AddToMean) hold, into `texel`'s B, G, R.
inline void MeanOfSums(const float* sum, uint8_t* texel) {
  const float weight = std::abs(sum[3]);
  for (int c = 0; c < 3; ++c) texel[c] = cv::saturate_cast<uint8_t>(sum[c] / weight);
}

// `update: mean` (and `sharp_mean`): AddToMean with `weight`, and the texel their mean; the
// stored quality is the best seen. Counts into `stats`.
inline void MeanTexel(const uint8_t* sample, float weight, float quality, bool provisional,
                      bool on_surface, uint8_t* texel, float* stored_quality, float* sum,
                      PaintUpdateStats* stats) {
  CompareWithStored(sample, texel, stats);
  if (texel[3] == 0 && on_surface) ++stats->newly_painted;
  AddToMean(sample, weight, provisional, sum);
  MeanOfSums(sum, texel);
  texel[3] = 255;
  *stored_quality = std::max(*stored_quality, quality);
  ++stats->written;
}

}  // namespace fresco
