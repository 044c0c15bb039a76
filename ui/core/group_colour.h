// Colours for grouping edits that stay put: a group's colour comes from a stable key (its
// lowest triangle index), not from its place in the list, so merging, splitting or moving
// triangles leaves every untouched group's colour as it was (a merged group keeps the
// colour of the part holding the lowest triangle). Pure logic, no ImGui or GL.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "pipeline/core/project.h"

namespace fresco {

// The group's key: its lowest triangle index (-1 for an empty group).
int StableGroupKey(const GroupSpec& group);

// An RGB colour (0..1) for a key: a hue from a hash of the key, so neighbouring keys get
// unrelated hues; saturation and value fixed so that the shading stays readable.
std::array<float, 3> GroupColour(int key);

// Every colour GroupColour can give (its hue takes 3600 steps), for checks against them.
std::vector<std::array<float, 3>> AllGroupColours();

// Picked triangles in the 3D view: stripes of kPickedRgb (white) and kPickedStripeRgb
// (black), drawn over the triangle rather than mixed with it, so that no group colour
// (saturated, with channels between 0.25 and 0.9) looks like a picked triangle.
inline constexpr std::array<float, 3> kPickedRgb = {1.0f, 1.0f, 1.0f};
inline constexpr std::array<float, 3> kPickedStripeRgb = {0.0f, 0.0f, 0.0f};

// The RGB distance (0..sqrt 3) of `rgb` to the nearest group colour.
float DistanceToNearestGroupColour(const std::array<float, 3>& rgb);

// (G) the key of every group, in order.
std::vector<int> StableGroupKeys(const std::vector<GroupSpec>& groups);

}  // namespace fresco
