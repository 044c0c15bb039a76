// A wall buffer for refinement tests: `width` x `height` texels of `texel_m`, facing a camera
// at the origin (looking down +z) from `depth_m`, centred on the optical axis.
#pragma once

#include "pipeline/paint/base_buffer.h"

namespace fresco {

inline BaseBuffer FrontalWall(int width, int height, double texel_m, double depth_m) {
  BaseBuffer wall;
  wall.texel_size_m = texel_m;
  wall.width = width, wall.height = height;
  wall.origin = Eigen::Vector3d(-0.5 * width * texel_m, -0.5 * height * texel_m, depth_m);
  wall.axis_u = Eigen::Vector3d::UnitX();
  wall.axis_v = Eigen::Vector3d::UnitY();
  wall.normal = -Eigen::Vector3d::UnitZ();
  return wall;
}

}  // namespace fresco
