// A small deterministic random generator for synthetic data: the same seed gives the same
// numbers on every platform and standard library (std::normal_distribution and friends are
// implementation-defined, so they are not used). SplitMix64 core; independent streams per
// purpose (path, noise, movers, ...) so that changing one option does not reshuffle the rest.
#pragma once

#include <cmath>
#include <cstdint>

namespace fresco {

class SynthRandom {
 public:
  // `stream` separates independent sequences drawn from the same user seed.
  explicit SynthRandom(uint64_t seed, uint64_t stream = 0)
      : state_(seed * 0x9E3779B97F4A7C15ull + stream * 0xD1B54A32D192ED03ull +
               0x632BE59BD9B4E019ull) {
    Next();
  }

  uint64_t Next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  // Uniform in [0, 1).
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  // Uniform integer in [lo, hi] (inclusive).
  int UniformInt(int lo, int hi) {
    return lo + static_cast<int>(Uniform() * (static_cast<double>(hi) - lo + 1.0));
  }
  // Standard normal (Box-Muller, both values used).
  double Normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u1 = Uniform();
    while (u1 <= 1e-300) u1 = Uniform();
    const double u2 = Uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2.0 * M_PI * u2);
    has_spare_ = true;
    return r * std::cos(2.0 * M_PI * u2);
  }
  double Normal(double mean, double stddev) { return mean + stddev * Normal(); }

 private:
  uint64_t state_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

// A smooth random signal: a sum of a few sinusoids with random frequencies and phases,
// scaled to unit RMS. `t` is normalized time (0 at the first frame, 1 at the last);
// frequencies are in cycles per unit time within [min_cycles, max_cycles].
class SmoothNoise {
 public:
  SmoothNoise() = default;
  SmoothNoise(SynthRandom* random, double min_cycles, double max_cycles, int terms = 4) {
    terms_ = terms < 1 ? 1 : (terms > kMaxTerms ? kMaxTerms : terms);
    double sum_sq = 0.0;
    for (int i = 0; i < terms_; ++i) {
      freq_[i] = random->Uniform(min_cycles, max_cycles);
      phase_[i] = random->Uniform(0.0, 2.0 * M_PI);
      amp_[i] = random->Uniform(0.5, 1.0);
      sum_sq += 0.5 * amp_[i] * amp_[i];  // mean of sin^2 is 1/2
    }
    const double norm = sum_sq > 0 ? 1.0 / std::sqrt(sum_sq) : 0.0;
    for (int i = 0; i < terms_; ++i) amp_[i] *= norm;
  }
  double operator()(double t) const {
    double v = 0.0;
    for (int i = 0; i < terms_; ++i) v += amp_[i] * std::sin(2.0 * M_PI * freq_[i] * t + phase_[i]);
    return v;
  }

 private:
  static constexpr int kMaxTerms = 8;
  int terms_ = 0;
  double freq_[kMaxTerms] = {}, phase_[kMaxTerms] = {}, amp_[kMaxTerms] = {};
};

}  // namespace fresco
