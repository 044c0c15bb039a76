// Which way is up in the app's 3D view. glTF models stand with +Y up; photogrammetry and
// scanning meshes (COLMAP, OpenMVS, Meshroom) are in their reconstruction's frame, where
// "up" is wherever the cameras' up happened to point, often -Y or sideways, so orbiting
// about +Y shows them upside down or on their side. The view takes up from the capture: the
// cameras' mean up direction (their -y axis), snapped to +Y when within 45 degrees of it.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "pipeline/core/rigid3.h"

namespace fresco {

struct OrbitFrame {
  Eigen::Vector3f up = Eigen::Vector3f::UnitY();
  Eigen::Vector3f side = Eigen::Vector3f::UnitX();   // yaw 90 degrees looks from here
  Eigen::Vector3f front = Eigen::Vector3f::UnitZ();  // yaw 0 looks from here
};

// +Y up (and X, Z around it) unless the poses' mean up is more than 45 degrees from +Y;
// then that up, with the front towards where the cameras are on average.
OrbitFrame OrbitFrameFromPoses(const std::vector<Rigid3d>& cam_from_world);

// Direction from the orbit centre to the eye at yaw/pitch (radians), and the screen's right
// and up directions there (for panning).
Eigen::Vector3f OrbitEyeDirection(const OrbitFrame& frame, float yaw, float pitch);
Eigen::Vector3f OrbitScreenRight(const OrbitFrame& frame, float yaw);
Eigen::Vector3f OrbitScreenUp(const OrbitFrame& frame, float yaw, float pitch);

}  // namespace fresco
