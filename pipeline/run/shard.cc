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

std::vector<int> AssignBuffersToShards(const std::vector<BaseBuffer>& buffers,
                                       const std::vector<int>& frames_seeing, int count) {
  std::vector<int> shard(buffers.size(), 0);
  if (count <= 1) return shard;
  std::vector<double> work(buffers.size());
  std::vector<Eigen::Vector3d> centre(buffers.size());
  for (size_t b = 0; b < buffers.size(); ++b) {
    const int frames = frames_seeing.empty() ? 1 : std::max(frames_seeing[b], 1);
    work[b] = static_cast<double>(std::max<long long>(buffers[b].num_surface_texels, 1)) * frames;
    centre[b] = 0.5 * (buffers[b].bounds_min + buffers[b].bounds_max);
  }
  std::vector<size_t> ids(buffers.size());
  std::iota(ids.begin(), ids.end(), 0);
  // Shards [first, first + n) take ids [begin, end).
  const std::function<void(size_t, size_t, int, int)> split = [&](size_t begin, size_t end,
                                                                  int first, int n) {
    if (n == 1 || end - begin <= 1) {
      for (size_t k = begin; k < end; ++k) shard[ids[k]] = first;
      return;
    }
    Eigen::Vector3d low = centre[ids[begin]], high = low;
    double total = 0;
    for (size_t k = begin; k < end; ++k) {
      low = low.cwiseMin(centre[ids[k]]), high = high.cwiseMax(centre[ids[k]]);
      total += work[ids[k]];
    }
    int axis = 0;
    (high - low).maxCoeff(&axis);
    std::sort(ids.begin() + begin, ids.begin() + end, [&](size_t a, size_t b) {
      return centre[a][axis] != centre[b][axis] ? centre[a][axis] < centre[b][axis] : a < b;
    });
    // The cut whose first side's work is nearest its shards' share (each side keeps a buffer).
    const int left = n / 2;
    const double target = total * left / n;
    size_t cut = begin + 1;
    double sum = work[ids[begin]], best = std::abs(sum - target);
    for (size_t k = begin + 1; k + 1 < end; ++k) {
      sum += work[ids[k]];
      if (std::abs(sum - target) < best) best = std::abs(sum - target), cut = k + 1;
    }
    split(begin, cut, first, left);
    split(cut, end, first + left, n - left);
  };
  split(0, ids.size(), 0, count);
  return shard;
}

}  // namespace fresco
