// A pose with an injected error, for the pose-verification tests: rotated by
// `rotation_deg` about `axis` (camera side) and its centre moved by `position_m` along it.
#pragma once

#include <cmath>

#include <Eigen/Geometry>

#include "pipeline/core/rigid3.h"

namespace fresco::testing {

inline Rigid3d Perturbed(const Rigid3d& cam_from_world, double rotation_deg, double position_m,
                         const Eigen::Vector3d& axis) {
  const Eigen::Quaterniond dq(Eigen::AngleAxisd(rotation_deg * M_PI / 180.0, axis.normalized()));
  const Eigen::Quaterniond rotation = (dq * cam_from_world.rotation).normalized();
  const Eigen::Vector3d centre = cam_from_world.Centre() + position_m * axis.normalized();
  return Rigid3d(rotation, -(rotation * centre));
}

}  // namespace fresco::testing
