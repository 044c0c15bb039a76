#include "ui/core/group_colour.h"

#include <algorithm>
#include <cmath>

namespace fresco {

int StableGroupKey(const GroupSpec& group) {
  if (group.triangles.empty()) return -1;
  return *std::min_element(group.triangles.begin(), group.triangles.end());
}

namespace {

constexpr uint32_t kHueSteps = 3600;

std::array<float, 3> ColourOfHue(float hue) {
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

}  // namespace

std::array<float, 3> GroupColour(int key) {
  // A 32-bit integer hash (xorshift-multiply) spreads consecutive keys over the hue circle.
  uint32_t h = static_cast<uint32_t>(key) + 0x9e3779b9u;
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return ColourOfHue(static_cast<float>(h % kHueSteps) / kHueSteps);
}

std::vector<std::array<float, 3>> AllGroupColours() {
  std::vector<std::array<float, 3>> colours;
  for (uint32_t i = 0; i < kHueSteps; ++i)
    colours.push_back(ColourOfHue(static_cast<float>(i) / kHueSteps));
  return colours;
}

float DistanceToNearestGroupColour(const std::array<float, 3>& rgb) {
  float nearest = 2;
  for (const auto& c : AllGroupColours())
    nearest = std::min(nearest, std::hypot(c[0] - rgb[0], c[1] - rgb[1], c[2] - rgb[2]));
  return nearest;
}

std::vector<int> StableGroupKeys(const std::vector<GroupSpec>& groups) {
  std::vector<int> keys;
  keys.reserve(groups.size());
  for (const GroupSpec& g : groups) keys.push_back(StableGroupKey(g));
  return keys;
}

}  // namespace fresco
