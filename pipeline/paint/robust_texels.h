// The robust background model's per-texel state and its update (background_model.h): two
// colour modes per texel with weights over a sliding window of samples. The state is kept as
// a structure of arrays (by texel number k) so that the update runs over many texels at once
// in the CPU's vector unit: the samples of a run of texels are gathered first, then the whole
// run is classified and learnt with no branch per texel, with the same arithmetic (and the
// same results to the bit) as one texel at a time.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

namespace fresco {

// Means are fixed point (x kRobustMeanScale), the variance grey levels^2 x 4.
inline constexpr float kRobustMeanScale = 64.0f;

struct RobustTexels {
  std::vector<uint16_t> mean[2][3];  // [mode][channel]: mode 0 = background, 1 = candidate
  std::vector<uint16_t> var4;        // background noise variance per channel, grey levels^2 x 4
  std::vector<uint16_t> samples;     // samples seen (saturates at 65535)
  std::vector<float> weight[2];      // fraction of the recent samples each mode explains

  void Assign(int texels);  // every texel unseen
  void Clear();
  bool empty() const { return samples.empty(); }
  // The background mean of texel k, grey levels.
  float Mean(int k, int channel) const { return mean[0][channel][k] * (1.0f / kRobustMeanScale); }
  // Copies texel `from`'s state to each `to` of the pairs (all read before any is written).
  void Move(const std::vector<std::pair<int, int>>& to_from);
};

struct RobustUpdateParams {
  float k2 = 9.0f;        // sigma_threshold^2
  float min_var = 36.0f;  // min_sigma^2
  int window = 40;        // window_frames
  int warmup = 8;         // warmup_frames
  float majority = 0.6f;  // majority
};

// Classifies and learns the samples of texels [begin, begin + n): `x` holds each channel's
// samples already divided by the frame's gain, `valid` 1 where the texel was sampled (the
// others keep their state). Out, per texel: `foreground` 1 when the sample is not the
// background mode (and the background is decided: it explains at least `majority` of the
// recent samples), `warming` 1 while the model is warming up, just changed its background
// or is undecided,
// `distance2` the squared RMS channel distance to the background before the update (1e30
// for a texel never seen).
void UpdateRobustTexels(const RobustUpdateParams& params, int begin, int n, const float* x0,
                        const float* x1, const float* x2, const uint8_t* valid,
                        RobustTexels* texels, uint8_t* foreground, uint8_t* warming,
                        float* distance2);

}  // namespace fresco
