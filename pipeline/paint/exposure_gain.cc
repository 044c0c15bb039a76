#include "pipeline/paint/exposure_gain.h"

#include <algorithm>
#include <cmath>

namespace fresco {
namespace {

// Values this far from black and saturation carry the exposure.
constexpr int kMinValue = 4, kMaxValue = 251;

double Median(std::vector<float> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// sample = gain * stored + offset fitted robustly: the median ratio and the median residual to
// start, then a few rounds of least squares weighted by Tukey's biweight (residuals beyond
// 3 robust sigmas, movers and misregistered texels, weigh nothing).
void FitAffine(const std::vector<float>& stored, const std::vector<float>& sample, double* gain,
               double* offset) {
  const size_t n = stored.size();
  std::vector<float> work(n);
  for (size_t i = 0; i < n; ++i) work[i] = sample[i] / stored[i];
  double a = Median(work);
  for (size_t i = 0; i < n; ++i) work[i] = static_cast<float>(sample[i] - a * stored[i]);
  double b = Median(work);
  for (int round = 0; round < 4; ++round) {
    for (size_t i = 0; i < n; ++i)
      work[i] = std::abs(static_cast<float>(sample[i] - a * stored[i] - b));
    const double cutoff = 3.0 * (1.4826 * Median(work) + 1.0);
    double sw = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (size_t i = 0; i < n; ++i) {
      const double u = work[i] / cutoff;
      if (u >= 1) continue;
      const double w = (1 - u * u) * (1 - u * u);
      const double x = stored[i], y = sample[i];
      sw += w, sx += w * x, sy += w * y, sxx += w * x * x, sxy += w * x * y;
    }
    const double det = sw * sxx - sx * sx;
    if (sw <= 0 || det <= 1e-9 * sw * sxx) break;  // no spread in the stored values: keep
    a = (sw * sxy - sx * sy) / det;
    b = (sy - a * sx) / sw;
  }
  *gain = a;
  *offset = b;
}

}  // namespace

ExposureGain EstimateExposureGain(const std::vector<BaseBuffer>& buffers,
                                  const std::vector<WarpedBuffer>& warped,
                                  const std::vector<PaintedBuffer>& painted,
                                  const std::vector<size_t>& seen, const ExposureOptions& options) {
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
  result.samples =
      static_cast<int>(std::min({samples[0].size(), samples[1].size(), samples[2].size()}));
  if (result.samples < options.min_samples) return result;
  for (int c = 0; c < 3; ++c) {
    double gain = 1, offset = 0;
    FitAffine(stored_values[c], samples[c], &gain, &offset);
    result.gain[c] = std::clamp(gain, options.min_gain, options.max_gain);
    result.offset[c] = std::clamp(offset, -options.max_offset, options.max_offset);
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
