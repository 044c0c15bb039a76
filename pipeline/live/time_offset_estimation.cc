#include "pipeline/live/time_offset_estimation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

namespace fresco {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double MedianInterval(const std::vector<Frame>& frames) {
  std::vector<double> dt;
  for (size_t i = 1; i < frames.size(); ++i) {
    const double d = frames[i].timestamp_s - frames[i - 1].timestamp_s;
    if (d > 0) dt.push_back(d);
  }
  if (dt.empty()) return 1.0 / 30.0;
  std::nth_element(dt.begin(), dt.begin() + dt.size() / 2, dt.end());
  return dt[dt.size() / 2];
}

bool Better(const TimeOffsetCandidate& a, const TimeOffsetCandidate& b) {
  if (!std::isfinite(b.score)) return std::isfinite(a.score);
  return std::isfinite(a.score) && a.score < b.score;
}

}  // namespace

TimeOffsetEstimate SearchTimeOffset(const std::vector<Frame>& frames,
                                    const TimeOffsetOptions& options, const ScoreOffset& score_offset) {
  const auto start = std::chrono::steady_clock::now();
  TimeOffsetEstimate result;
  result.offset_s = options.centre_s;
  result.frames = static_cast<int>(frames.size());
  const double period = MedianInterval(frames);
  const double step = options.step_s > 0 ? options.step_s : period;
  auto score = [&](double offset) {
    TimeOffsetCandidate c = score_offset(offset);
    if (c.frames_scored < options.min_frames) c.score = kNaN;
    result.candidates.push_back(c);
    return c;
  };
  // Coarse: one frame period over the whole range.
  const int half = std::max(1, static_cast<int>(std::ceil(options.search_s / step)));
  std::vector<TimeOffsetCandidate> coarse;
  size_t best_at = 0;
  for (int i = -half; i <= half; ++i) {
    coarse.push_back(score(options.centre_s + i * step));
    if (Better(coarse.back(), coarse[best_at])) best_at = coarse.size() - 1;
  }
  const TimeOffsetCandidate& best = coarse[best_at];
  if (!std::isfinite(best.score)) {
    result.note =
        "no candidate offset could be scored (too few frames with poses, or the "
        "frames see none of the model)";
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
  }
  // Fine: a quarter step around the best. Its ends (one step away) and centre are coarse
  // candidates already scored, unless the best is at the end of the coarse range.
  const double fine = step / 4;
  std::vector<TimeOffsetCandidate> around;
  for (int i = -4; i <= 4; ++i) {
    const long coarse_at = static_cast<long>(best_at) + i / 4;
    if (i % 4 == 0 && coarse_at >= 0 && coarse_at < static_cast<long>(coarse.size()))
      around.push_back(coarse[coarse_at]);
    else
      around.push_back(score(best.offset_s + i * fine));
  }
  size_t k = 0;
  for (size_t i = 1; i < around.size(); ++i)
    if (Better(around[i], around[k])) k = i;
  double offset = around[k].offset_s;
  // Parabola through the best fine score and its neighbours.
  if (k > 0 && k + 1 < around.size() && std::isfinite(around[k - 1].score) &&
      std::isfinite(around[k + 1].score)) {
    const double a = around[k - 1].score, b = around[k].score, c = around[k + 1].score;
    const double curvature = a - 2 * b + c;
    if (curvature > 0) offset += 0.5 * fine * (a - c) / curvature;
  }
  std::vector<double> scores;
  for (const TimeOffsetCandidate& c : result.candidates)
    if (std::isfinite(c.score)) scores.push_back(c.score);
  std::nth_element(scores.begin(), scores.begin() + scores.size() / 2, scores.end());
  result.ok = true;
  result.offset_s = offset;
  result.score = around[k].score;
  result.contrast = scores[scores.size() / 2] - around[k].score;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace fresco
