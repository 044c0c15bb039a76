#include "pipeline/run/shard.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
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

std::vector<int> AssignBuffersToShards(const std::vector<BaseBuffer>& buffers, int count) {
  std::vector<int> shard(buffers.size(), 0);
  if (count <= 1) return shard;
  std::vector<size_t> order(buffers.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return buffers[a].num_surface_texels > buffers[b].num_surface_texels;
  });
  std::vector<long long> load(count, 0);
  for (size_t b : order) {
    const int least = static_cast<int>(std::min_element(load.begin(), load.end()) - load.begin());
    shard[b] = least;
    load[least] += std::max<long long>(buffers[b].num_surface_texels, 1);
  }
  return shard;
}

}  // namespace fresco
