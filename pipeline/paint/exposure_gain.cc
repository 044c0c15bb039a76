#include "pipeline/paint/exposure_gain.h"

#include <algorithm>

namespace fresco {
namespace {

// Values this far from black and saturation carry the exposure.
constexpr int kMinValue = 4, kMaxValue = 251;

// The q-quantile (0..1) of v (reorders v).
double Quantile(std::vector<float>* v, double q) {
  const size_t k = std::min(v->size() - 1, static_cast<size_t>(q * v->size()));
  std::nth_element(v->begin(), v->begin() + k, v->end());
  return (*v)[k];
}

}  // namespace

ExposureGain EstimateExposureGain(const std::vector<BaseBuffer>& buffers,
                                  const std::vector<WarpedBuffer>& warped,
                                  const std::vector<PaintedBuffer>& painted,
                                  const std::vector<size_t>& seen,
                                  const ExposureOptions& options) {
  long long candidates = 0;  // valid texels (an upper bound on those in common)
  for (size_t b : seen) candidates += warped[b].visible;
  const long long stride = std::max<long long>(1, candidates / options.max_samples);
  std::vector<float> samples[3], stored_values[3];
  long long n = 0;
  for (size_t b : seen) {
    const BaseBuffer& buffer = buffers[b];
    const uint8_t* valid = warped[b].valid.data;
    const cv::Vec3b* sample = warped[b].bgr.ptr<cv::Vec3b>();
    const cv::Vec4b* stored = painted[b].bgra.ptr<cv::Vec4b>();
    for (const BaseBuffer::Chunk& chunk : buffer.chunks) {
      if (!warped[b].MayBeValid(chunk)) continue;
      for (int k = chunk.begin; k < chunk.end; ++k) {
        const int idx = buffer.texel_index[k];
        if (!valid[idx] || stored[idx][3] == 0 || !buffer.on_surface[k]) continue;
        if (n++ % stride != 0) continue;
        for (int c = 0; c < 3; ++c) {
          const int s = sample[idx][c], o = stored[idx][c];
          if (s < kMinValue || s > kMaxValue || o < kMinValue || o > kMaxValue) continue;
          samples[c].push_back(static_cast<float>(s));
          stored_values[c].push_back(static_cast<float>(o));
        }
      }
    }
  }
  ExposureGain result;
  result.samples = static_cast<int>(std::min({samples[0].size(), samples[1].size(), samples[2].size()}));
  if (result.samples < options.min_samples) return result;
  for (int c = 0; c < 3; ++c) {
    const double s_lo = Quantile(&samples[c], 0.2), s_mid = Quantile(&samples[c], 0.5),
                 s_hi = Quantile(&samples[c], 0.8);
    const double o_lo = Quantile(&stored_values[c], 0.2),
                 o_mid = Quantile(&stored_values[c], 0.5),
                 o_hi = Quantile(&stored_values[c], 0.8);
    const double gain = o_hi - o_lo > 4 ? (s_hi - s_lo) / (o_hi - o_lo) : s_mid / std::max(o_mid, 1.0);
    result.gain[c] = std::clamp(gain, options.min_gain, options.max_gain);
    result.offset[c] =
        std::clamp(s_mid - result.gain[c] * o_mid, -options.max_offset, options.max_offset);
  }
  result.applied = true;
  return result;
}

void ApplyExposureGain(const ExposureGain& gain, const std::vector<size_t>& seen,
                       std::vector<WarpedBuffer>* warped) {
  if (!gain.applied) return;
  // stored = (sample - offset) / gain, per channel.
  cv::Matx34f undo = cv::Matx34f::zeros();
  for (int c = 0; c < 3; ++c) {
    undo(c, c) = static_cast<float>(1.0 / gain.gain[c]);
    undo(c, 3) = static_cast<float>(-gain.offset[c] / gain.gain[c]);
  }
  for (size_t b : seen) {
    WarpedBuffer& w = (*warped)[b];
    if (w.valid_box.empty()) continue;
    cv::Mat roi = w.bgr(w.valid_box);
    cv::transform(roi, roi, undo);  // saturating, rounded; invalid texels are never read
  }
}

}  // namespace fresco
