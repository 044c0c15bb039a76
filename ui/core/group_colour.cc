#include "ui/core/group_colour.h"

#include <algorithm>
#include <cmath>

namespace fresco {

int StableGroupKey(const GroupSpec& group) {
  if (group.triangles.empty()) return -1;
  return *std::min_element(group.triangles.begin(), group.triangles.end());
}

std::array<float, 3> GroupColour(int key) {
  // A 32-bit integer hash (xorshift-multiply) spreads consecutive keys over the hue circle.
  uint32_t h = static_cast<uint32_t>(key) + 0x9e3779b9u;
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  const float hue = static_cast<float>(h % 3600u) / 3600.0f;
  std::array<float, 3> rgb;
  const float offsets[3] = {0.0f, 2.0f / 3.0f, 1.0f / 3.0f};
  for (int c = 0; c < 3; ++c) {
    float t = hue + offsets[c];
    t -= std::floor(t);
    const float ramp = std::clamp(std::abs(t * 6.0f - 3.0f) - 1.0f, 0.0f, 1.0f);
    rgb[c] = ramp * 0.65f + 0.25f;
  }
  return rgb;
}

std::vector<int> StableGroupKeys(const std::vector<GroupSpec>& groups) {
  std::vector<int> keys;
  keys.reserve(groups.size());
  for (const GroupSpec& g : groups) keys.push_back(StableGroupKey(g));
  return keys;
}

}  // namespace fresco
