#include "pipeline/paint/robust_texels.h"

#include <algorithm>
#include <cstring>
#include <utility>

namespace fresco {
namespace {

constexpr float kInvScale = 1.0f / kRobustMeanScale;
constexpr float kMaxMean = 65535.0f / kRobustMeanScale;

}  // namespace

void RobustTexels::Assign(int texels) {
  const size_t n = static_cast<size_t>(texels);
  for (auto& mode : mean)
    for (auto& channel : mode) channel.assign(n, 0);
  var4.assign(n, 0);
  samples.assign(n, 0);
  weight[0].assign(n, 0.0f);
  weight[1].assign(n, 0.0f);
}

void RobustTexels::Clear() { Assign(0); }

void RobustTexels::Move(const std::vector<std::pair<int, int>>& to_from) {
  const auto move = [&](auto* values) {
    using T = typename std::decay_t<decltype(*values)>::value_type;
    std::vector<T> read(to_from.size());
    for (size_t i = 0; i < to_from.size(); ++i) read[i] = (*values)[to_from[i].second];
    for (size_t i = 0; i < to_from.size(); ++i) (*values)[to_from[i].first] = read[i];
  };
  for (auto& mode : mean)
    for (auto& channel : mode) move(&channel);
  move(&var4);
  move(&samples);
  move(&weight[0]);
  move(&weight[1]);
}

namespace {

// Every function taking or returning a vector below is inlined: no vector crosses a call, so
// the note that such calls would differ between targets does not apply.
#pragma GCC diagnostic ignored "-Wpsabi"

// 8 texels in the lanes of a vector (GCC's vector extensions: plain C++ operators on whole
// vectors, compiled to whatever vector instructions the function's target has).
using Floats = float __attribute__((vector_size(32)));
using Ints = int32_t __attribute__((vector_size(32)));
using Shorts = uint16_t __attribute__((vector_size(16)));
using Bytes = uint8_t __attribute__((vector_size(8)));
constexpr int kLanes = 8;

// Where 8 consecutive texels' state, samples and results are.
struct Lanes {
  uint16_t* mean[2][3];
  uint16_t* var4;
  uint16_t* samples;
  float* weight[2];
  const float* x[3];
  const uint8_t* valid;
  uint8_t* foreground;
  uint8_t* warming;
  float* distance2;
};

// The same places, `i` texels on.
[[gnu::always_inline]] inline Lanes At(const Lanes& l, int i) {
  Lanes at = l;
  for (auto& mode : at.mean)
    for (auto*& channel : mode) channel += i;
  at.var4 += i, at.samples += i, at.weight[0] += i, at.weight[1] += i;
  for (auto*& channel : at.x) channel += i;
  at.valid += i, at.foreground += i, at.warming += i, at.distance2 += i;
  return at;
}

template <class V>
[[gnu::always_inline]] inline V Load(const void* p) {
  V v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}
template <class V>
[[gnu::always_inline]] inline void Store(void* p, const V& v) {
  std::memcpy(p, &v, sizeof(v));
}
[[gnu::always_inline]] inline Ints LoadShorts(const uint16_t* p) {
  return __builtin_convertvector(Load<Shorts>(p), Ints);
}
[[gnu::always_inline]] inline void StoreShorts(uint16_t* p, Ints v) {
  Store(p, __builtin_convertvector(v, Shorts));
}
[[gnu::always_inline]] inline Floats ToFloats(Ints v) { return __builtin_convertvector(v, Floats); }
// std::min and std::max, lane by lane (the same operand on ties).
[[gnu::always_inline]] inline Floats Min(Floats a, Floats b) { return b < a ? b : a; }
[[gnu::always_inline]] inline Floats Max(Floats a, Floats b) { return a < b ? b : a; }
[[gnu::always_inline]] inline Ints Min(Ints a, Ints b) { return b < a ? b : a; }

// A mean in fixed point (clamped to its range, rounded) and a variance as var4 (rounded,
// saturated), lane by lane.
[[gnu::always_inline]] inline Ints ToFixedLanes(Floats value) {
  const Floats clamped = Min(Max(value, Floats{} + 0.0f), Floats{} + kMaxMean);
  return __builtin_convertvector(clamped * kRobustMeanScale + 0.5f, Ints);
}
[[gnu::always_inline]] inline Ints ToVar4Lanes(Floats var) {
  return __builtin_convertvector(Min(var * 4.0f, Floats{} + 65535.0f) + 0.5f, Ints);
}

// The update of 8 texels: the per-texel rule with every branch turned into a select (each
// candidate value computed, then chosen lane by lane), operation for operation the same
// arithmetic, so the same results as one texel at a time.
[[gnu::always_inline]] inline void UpdateLanes(const RobustUpdateParams& params, const Lanes& l) {
  const Ints sampled = __builtin_convertvector(Load<Bytes>(l.valid), Ints) != 0;
  const Floats y0 = Load<Floats>(l.x[0]), y1 = Load<Floats>(l.x[1]), y2 = Load<Floats>(l.x[2]);
  const Ints o00 = LoadShorts(l.mean[0][0]), o01 = LoadShorts(l.mean[0][1]),
             o02 = LoadShorts(l.mean[0][2]);
  const Ints o10 = LoadShorts(l.mean[1][0]), o11 = LoadShorts(l.mean[1][1]),
             o12 = LoadShorts(l.mean[1][2]);
  const Ints o_var4 = LoadShorts(l.var4), seen = LoadShorts(l.samples);
  const Floats w0 = Load<Floats>(l.weight[0]), w1 = Load<Floats>(l.weight[1]);
  const Floats alpha = 1.0f / ToFloats(Min(seen + 1, Ints{} + params.window));
  const Floats var = Max(ToFloats(o_var4) * 0.25f, Floats{} + params.min_var);
  const Floats a0 = ToFloats(o00) * kInvScale, a1 = ToFloats(o01) * kInvScale,
               a2 = ToFloats(o02) * kInvScale;
  const Floats b0 = ToFloats(o10) * kInvScale, b1 = ToFloats(o11) * kInvScale,
               b2 = ToFloats(o12) * kInvScale;
  const Floats e0 = y0 - a0, e1 = y1 - a1, e2 = y2 - a2;
  const Floats f0 = y0 - b0, f1 = y1 - b1, f2 = y2 - b2;
  const Floats d0 = seen > 0 ? (e0 * e0 + e1 * e1 + e2 * e2) * (1.0f / 3.0f) : Floats{} + 1e30f;
  const Floats d1 = (f0 * f0 + f1 * f1 + f2 * f2) * (1.0f / 3.0f);
  const Floats threshold = params.k2 * var;
  // The sample's mode: the background if close enough, else the candidate, else it
  // replaces the candidate.
  const Ints match0 = d0 <= threshold;
  const Ints match1 = ~match0 & (w1 > 0.0f) & (d1 <= threshold);
  const Floats keep = 1.0f - alpha;
  const Floats k0 = w0 * keep, k1 = w1 * keep;
  const Floats u0 = match0 ? k0 + alpha : k0;
  const Floats u1 = match1 ? k1 + alpha : (match0 ? k1 : alpha);
  const Floats rho = Min(Floats{} + 1.0f, alpha / (match0 ? u0 : u1));
  const Ints n00 = match0 ? ToFixedLanes(a0 + rho * (y0 - a0)) : o00;
  const Ints n01 = match0 ? ToFixedLanes(a1 + rho * (y1 - a1)) : o01;
  const Ints n02 = match0 ? ToFixedLanes(a2 + rho * (y2 - a2)) : o02;
  const Ints n10 = match0 ? o10 : match1 ? ToFixedLanes(b0 + rho * (y0 - b0)) : ToFixedLanes(y0);
  const Ints n11 = match0 ? o11 : match1 ? ToFixedLanes(b1 + rho * (y1 - b1)) : ToFixedLanes(y1);
  const Ints n12 = match0 ? o12 : match1 ? ToFixedLanes(b2 + rho * (y2 - b2)) : ToFixedLanes(y2);
  const Ints v4 = match0 ? ToVar4Lanes(var + rho * (d0 - var)) : o_var4;
  // The candidate now explains more: it is background.
  const Ints flip = u1 >= u0;
  const Ints after = Min(seen + 1, Ints{} + 65535);
  const Ints min_var4 = ToVar4Lanes(Floats{} + params.min_var);
  StoreShorts(l.mean[0][0], sampled ? (flip ? n10 : n00) : o00);
  StoreShorts(l.mean[0][1], sampled ? (flip ? n11 : n01) : o01);
  StoreShorts(l.mean[0][2], sampled ? (flip ? n12 : n02) : o02);
  StoreShorts(l.mean[1][0], sampled ? (flip ? n00 : n10) : o10);
  StoreShorts(l.mean[1][1], sampled ? (flip ? n01 : n11) : o11);
  StoreShorts(l.mean[1][2], sampled ? (flip ? n02 : n12) : o12);
  Store(l.weight[0], sampled ? (flip ? u1 : u0) : w0);
  Store(l.weight[1], sampled ? (flip ? u0 : u1) : w1);
  StoreShorts(l.var4, sampled ? (flip ? min_var4 : v4) : o_var4);
  StoreShorts(l.samples, sampled ? after : seen);
  // Foreground: the sample is not (after a flip: no longer) the background's.
  // Undecided: the background explains too small a share of the recent samples (the texel
  // shows two things about equally often, e.g. a slow mover over it for as long as not).
  // The model neither masks nor trusts such a sample: it paints provisionally.
  const Ints undecided = (flip ? u1 : u0) < params.majority;
  const Ints foreground = sampled & (match0 == flip) & ~undecided;
  // A texel whose background just changed holds a stale paint: provisional too.
  const Ints warming = sampled & ((after < params.warmup) | (flip & (seen > 0)) | undecided);
  Store(l.foreground, __builtin_convertvector(foreground & 1, Bytes));
  Store(l.warming, __builtin_convertvector(warming & 1, Bytes));
  Store(l.distance2, d0);
}

}  // namespace

// Vector code for 8 texels at a time: AVX2 where the CPU has it (chosen when the program
// starts), else SSE2; a last run of fewer than 8 is copied into 8 lanes and back.
__attribute__((target_clones("avx2", "default"))) void UpdateRobustTexels(
    const RobustUpdateParams& params, int begin, int n, const float* x0, const float* x1,
    const float* x2, const uint8_t* valid, RobustTexels* texels, uint8_t* foreground,
    uint8_t* warming, float* distance2) {
  // Where the run's state, samples and results are; then 8 texels at a time from there.
  Lanes run;
  for (int m = 0; m < 2; ++m)
    for (int c = 0; c < 3; ++c) run.mean[m][c] = texels->mean[m][c].data() + begin;
  run.var4 = texels->var4.data() + begin;
  run.samples = texels->samples.data() + begin;
  run.weight[0] = texels->weight[0].data() + begin;
  run.weight[1] = texels->weight[1].data() + begin;
  run.x[0] = x0, run.x[1] = x1, run.x[2] = x2;
  run.valid = valid;
  run.foreground = foreground, run.warming = warming, run.distance2 = distance2;
  int i = 0;
  for (; i + kLanes <= n; i += kLanes) UpdateLanes(params, At(run, i));
  const int rest = n - i;
  if (rest == 0) return;
  // The last texels in lanes of their own (unsampled lanes change nothing).
  const Lanes from = At(run, i);
  uint16_t mean[2][3][kLanes] = {}, var4[kLanes] = {}, samples[kLanes] = {};
  float weight[2][kLanes] = {}, x[3][kLanes] = {}, d2[kLanes];
  uint8_t sampled[kLanes] = {}, fg[kLanes], warm[kLanes];
  Lanes tail;
  for (int m = 0; m < 2; ++m)
    for (int c = 0; c < 3; ++c) tail.mean[m][c] = mean[m][c];
  tail.var4 = var4, tail.samples = samples, tail.weight[0] = weight[0], tail.weight[1] = weight[1];
  tail.x[0] = x[0], tail.x[1] = x[1], tail.x[2] = x[2];
  tail.valid = sampled, tail.foreground = fg, tail.warming = warm, tail.distance2 = d2;
  for (int j = 0; j < rest; ++j) {
    for (int m = 0; m < 2; ++m)
      for (int c = 0; c < 3; ++c) mean[m][c][j] = from.mean[m][c][j];
    var4[j] = from.var4[j], samples[j] = from.samples[j];
    weight[0][j] = from.weight[0][j], weight[1][j] = from.weight[1][j];
    for (int c = 0; c < 3; ++c) x[c][j] = from.x[c][j];
    sampled[j] = from.valid[j];
  }
  UpdateLanes(params, tail);
  for (int j = 0; j < rest; ++j) {
    for (int m = 0; m < 2; ++m)
      for (int c = 0; c < 3; ++c) from.mean[m][c][j] = mean[m][c][j];
    from.var4[j] = var4[j], from.samples[j] = samples[j];
    from.weight[0][j] = weight[0][j], from.weight[1][j] = weight[1][j];
    from.foreground[j] = fg[j], from.warming[j] = warm[j], from.distance2[j] = d2[j];
  }
}

}  // namespace fresco
