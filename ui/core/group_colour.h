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

// (G) the key of every group, in order.
std::vector<int> StableGroupKeys(const std::vector<GroupSpec>& groups);

}  // namespace fresco
