// Background stage (paper §3.4, selective texture painting): a background model per texel of
// every base buffer, so it works for moving cameras (each frame is first warped into the
// buffer, which is static relative to the model). Each frame's warped samples are compared
// with the model; foreground texels (people, cars, the paper's yellow sphere) are masked and
// the paint stage leaves them alone. Two models (BackgroundOptions::mode):
//   average  the paper: the linear average of each texel's first `training_frames` samples,
//            then image subtraction with a fixed threshold (frozen after training).
//   robust   two colour modes per texel with weights over a sliding window of samples
//            (Stauffer-Grimson style, two components): the background is the heavier mode,
//            so a texel converges to what it shows most of the time whatever came first;
//            foreground beyond `sigma_threshold` times the texel's own noise; every frame is
//            divided by its global gain (median sample/background ratio: exposure changes).
// Memory is fixed per texel (robust 24 bytes, average 8), whatever the video's length.
// Texels still warming up (fewer samples than the model needs) paint provisionally: their
// stored quality is marked (negated) so that the first trusted background sample replaces it,
// while among provisional samples the sharper ones are kept.
// The mask is cleaned: foreground blobs smaller than `min_blob_texels` are dropped (noise),
// the rest is dilated by `dilate_texels` (anti-aliased edges, shadows, the model's lag).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/core/project.h"
#include "pipeline/paint/base_buffer.h"
#include "pipeline/paint/frame_warp.h"
#include "pipeline/paint/robust_texels.h"

namespace fresco {

// One buffer's segmentation of one frame.
struct BackgroundFrame {
  cv::Mat foreground;  // CV_8U, buffer size: 255 = foreground after cleaning (not painted)
  cv::Mat warming;     // CV_8U, buffer size: 255 = sampled this frame, model still warming up
  // CV_8U, buffer size: `foreground` and the texels near a mover found across views
  // (BackgroundOptions::mover_margin); made only where near_movers > 0.
  cv::Mat kept_out;
  cv::Mat difference;      // CV_8U (debug only): RMS colour distance to the background x 2
  int observed = 0;        // texels sampled this frame (valid in the warped buffer)
  int foreground_raw = 0;  // ... classified foreground before cleaning
  int masked = 0;          // ... masked after cleaning (small blobs out, margin in) and growth
  int masked_ungrown = 0;  // ... masked after cleaning, before growth (the model's own verdict)
  int warming_up = 0;      // ... whose model is still warming up (painted provisionally)
  int blobs_removed = 0;   // foreground blobs smaller than min_blob_texels
  int near_movers = 0;     // ... kept out only for the margin around a mover (kept_out)
};

// Histogram of log2(sample / background) grey ratios over all buffers of a frame, for the
// frame's global gain (exposure) estimate.
struct GainHistogram {
  static constexpr int kBins = 512;  // log2 ratio in [-2, 2): 0.0078 per bin (0.5 %)
  std::array<int, kBins> bins = {};
  long long count = 0;
  // The median ratio, or 1 when fewer than `min_samples` samples were seen.
  float MedianGain(long long min_samples = 256) const;
};

// Every how many texels a frame's gain is sampled when `visible` texels are seen: every 4th,
// and on large meshes so that about 65,536 are (a median over more moves by less than a bin;
// on the refined Sceaux mesh every 4th texel took 3-4 ms a frame).
int GainStride(long long visible);

// The background model of one base buffer. Init once, then per frame (optionally)
// AccumulateGain over all buffers, then Update with the frame's gain.
class BufferBackground {
 public:
  void Init(const BaseBuffer& buffer, const BackgroundOptions& options);
  // Adds this buffer's samples (every `stride`th texel with a model, GainStride) to the gain
  // histogram.
  void AccumulateGain(const BaseBuffer& buffer, const WarpedBuffer& warped, int stride,
                      GainHistogram* histogram) const;
  // Classifies the warped samples, updates the model with them, cleans the mask.
  // `gain`: the frame's exposure relative to the model (robust mode; 1 = none). `grow`: the
  // foreground then grows by colour (BackgroundOptions::grow, resolved by the caller).
  // `movers` (optional, CV_8U, buffer size): texels the frame's movers found across views
  // cover (mover_masks.h); those connected to the foreground the model flags join it.
  // `agreed` (optional, the same): texels whose pixels the frames near it agree with; growth
  // does not start from them (a ghost: the background where a mover the model learned was).
  void Update(const BaseBuffer& buffer, const WarpedBuffer& warped, float gain, bool debug,
              bool grow, BackgroundFrame* frame, const cv::Mat* movers = nullptr,
              const cv::Mat* agreed = nullptr);
  // The background estimate (CV_8UC3, buffer size, black where never seen).
  cv::Mat Image(const BaseBuffer& buffer) const;
  // Moves the model with its buffer (refine_anchor.h): the texel at q (in `roi`) takes the
  // state of the texel nearest to q + field(q - roi.tl()) (CV_32FC2, roi size), when there
  // is one.
  void Move(const BaseBuffer& buffer, const cv::Rect& roi, const cv::Mat& field);
  // Each array the model holds (`f` called with the cv::Mat or std::vector): a saved painting
  // state stores them packed (painting_state.cc).
  template <typename F>
  void ForEachArray(F f) {
    f(raw_), f(raw_set_), f(texel_at_), f(average_), f(robust_.var4), f(robust_.samples);
    for (auto& mode : robust_.mean)
      for (std::vector<uint16_t>& channel : mode) f(channel);
    for (std::vector<float>& weight : robust_.weight) f(weight);
  }

  // Per-texel state of the average model (by texel number k, not buffer index); the robust
  // model's is RobustTexels.
  struct AverageTexel {
    uint16_t sum[3];  // sum of the training samples
    uint16_t count;   // training samples so far
  };

 private:
  struct ChunkStats;
  void Classify(const BaseBuffer& buffer, const WarpedBuffer& warped, float gain, bool debug,
                const BaseBuffer::Chunk& chunk, ChunkStats* stats, BackgroundFrame* frame);
  void Clean(const cv::Rect& roi, BackgroundFrame* frame);

  BackgroundOptions options_;
  RobustTexels robust_;
  std::vector<AverageTexel> average_;
  cv::Mat raw_;                   // CV_8U: this frame's foreground before cleaning
  std::vector<uint8_t> raw_set_;  // per chunk: raw_ may hold foreground there
  std::vector<int> texel_at_;     // texel number k by buffer index, -1 for none (built by Move)
};

}  // namespace fresco
