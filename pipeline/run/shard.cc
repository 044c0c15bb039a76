#include "pipeline/run/shard.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <numeric>

namespace fresco {
namespace {

// A whole non-negative decimal number, digits only.
bool ParseCount(const std::string& text, long* value) {
  if (text.empty() || text.size() > 9 ||
      !std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return false;
  *value = std::strtol(text.c_str(), nullptr, 10);
  return true;
}

}  // namespace

Status ParseShardSpec(const std::string& text, const std::string& what, ShardSpec* spec) {
  const size_t slash = text.find('/');
  long index = -1, count = -1;
  if (slash == std::string::npos || !ParseCount(text.substr(0, slash), &index) ||
      !ParseCount(text.substr(slash + 1), &count))
    return Status::Error(what + ": '" + text + "' is not I/N (shard I of N, e.g. 0/4)");
  if (count < 1) return Status::Error(what + ": '" + text + "': N must be at least 1");
  if (index >= count)
    return Status::Error(what + ": '" + text + "': I must be in 0.." + std::to_string(count - 1));
  spec->index = static_cast<int>(index);
  spec->count = static_cast<int>(count);
  return Status::Ok();
}

std::string SettingsHash(const Project& project) {
  const std::string fingerprint = ProjectToJsonText(project);
  unsigned long long hash = 1469598103934665603ULL;  // FNV-1a
  for (unsigned char c : fingerprint) hash = (hash ^ c) * 1099511628211ULL;
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", hash);
  return hex;
}

void BufferViews::Mark(size_t buffers, size_t b, int v) {
  const size_t words = (static_cast<size_t>(num_views) + 63) / 64;
  if (seen.size() != buffers) seen.assign(buffers, std::vector<unsigned long long>(words, 0));
  seen[b][v / 64] |= 1ULL << (v % 64);
}

int BufferViews::Count(size_t b) const {
  int n = 0;
  if (b < seen.size())
    for (unsigned long long w : seen[b]) n += __builtin_popcountll(w);
  return n;
}

std::vector<int> AssignBuffersToShards(const std::vector<BaseBuffer>& buffers,
                                       const BufferViews& views, const ShardCosts& costs,
                                       int count) {
  std::vector<int> shard(buffers.size(), 0);
  if (count <= 1) return shard;
  const bool with_views = views.num_views > 0 && views.seen.size() == buffers.size();
  const size_t words = with_views ? views.seen[0].size() : 0;
  const double frame_work = costs.per_frame * views.frames_per_view;
  std::vector<double> work(buffers.size());
  std::vector<Eigen::Vector3d> centre(buffers.size());
  for (size_t b = 0; b < buffers.size(); ++b) {
    const double texels =
        static_cast<double>(std::max<long long>(buffers[b].num_surface_texels, 1));
    work[b] = with_views ? texels * (costs.per_texel +
                                     costs.per_texel_frame * views.Count(b) * views.frames_per_view)
                         : texels;
    centre[b] = 0.5 * (buffers[b].bounds_min + buffers[b].bounds_max);
  }
  std::vector<size_t> ids(buffers.size());
  std::iota(ids.begin(), ids.end(), 0);
  const bool with_boxes = with_views && views.boxes.size() == buffers.size();
  const double window_work = costs.per_frame_window * views.frames_per_view;
  // The work of ids [begin, k) for every k in (begin, end] (from_end: of ids [k, end) for k in
  // [begin, end)), at index k - begin - 1 (from_end: k - begin).
  const auto side_work = [&](size_t begin, size_t end, bool from_end) {
    std::vector<double> out(end - begin);
    std::vector<unsigned long long> seen(words, 0);
    // Per view, the box of the buffers' boxes so far (empty: x0 > x1), and the sum of their areas.
    std::vector<std::array<float, 4>> window(with_boxes ? views.num_views : 0,
                                             std::array<float, 4>{1, 1, 0, 0});
    const auto area = [](const std::array<float, 4>& w) {
      return w[0] < w[2] && w[1] < w[3] ? static_cast<double>(w[2] - w[0]) * (w[3] - w[1]) : 0.0;
    };
    double sum = 0, windows = 0;
    for (size_t step = 0; step < end - begin; ++step) {
      const size_t id = ids[from_end ? end - 1 - step : begin + step];
      sum += work[id];
      int frames = 0;
      for (size_t w = 0; w < words; ++w)
        frames += __builtin_popcountll(seen[w] |= views.seen[id][w]);
      if (with_boxes)
        for (const auto& [v, box] : views.boxes[id]) {
          std::array<float, 4>& w = window[v];
          windows -= area(w);
          w = {std::min(w[0], box[0]), std::min(w[1], box[1]), std::max(w[2], box[2]),
               std::max(w[3], box[3])};
          windows += area(w);
        }
      out[from_end ? end - begin - 1 - step : step] =
          sum + frame_work * frames + window_work * (with_boxes ? windows : frames);
    }
    return out;
  };
  // Shards [first, first + n) take ids [begin, end).
  const std::function<void(size_t, size_t, int, int)> split = [&](size_t begin, size_t end,
                                                                  int first, int n) {
    if (n == 1 || end - begin <= 1) {
      for (size_t k = begin; k < end; ++k) shard[ids[k]] = first;
      return;
    }
    Eigen::Vector3d low = centre[ids[begin]], high = low;
    for (size_t k = begin; k < end; ++k)
      low = low.cwiseMin(centre[ids[k]]), high = high.cwiseMax(centre[ids[k]]);
    int axis = 0;
    (high - low).maxCoeff(&axis);
    std::sort(ids.begin() + begin, ids.begin() + end, [&](size_t a, size_t b) {
      return centre[a][axis] != centre[b][axis] ? centre[a][axis] < centre[b][axis] : a < b;
    });
    // The cut (each side keeps a buffer) whose larger side's work per shard is least.
    const int left = n / 2;
    const std::vector<double> first_side = side_work(begin, end, false);
    const std::vector<double> second_side = side_work(begin, end, true);
    size_t cut = begin + 1;
    double best = -1;
    for (size_t k = begin + 1; k < end; ++k) {
      const double larger =
          std::max(first_side[k - begin - 1] / left, second_side[k - begin] / (n - left));
      if (best < 0 || larger < best) best = larger, cut = k;
    }
    split(begin, cut, first, left);
    split(cut, end, first + left, n - left);
  };
  split(0, ids.size(), 0, count);
  return shard;
}

}  // namespace fresco
