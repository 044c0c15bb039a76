#include "ui/core/orbit_frame.h"

#include <cmath>

#include <Eigen/Geometry>

namespace fresco {

OrbitFrame OrbitFrameFromPoses(const std::vector<Rigid3d>& cam_from_world) {
  OrbitFrame frame;
  Eigen::Vector3d up_sum = Eigen::Vector3d::Zero(), back_sum = Eigen::Vector3d::Zero();
  for (const Rigid3d& pose : cam_from_world) {
    const Eigen::Matrix3d world_from_cam = pose.RotationMatrix().transpose();
    up_sum -= world_from_cam.col(1);    // camera y points down
    back_sum -= world_from_cam.col(2);  // from the scene towards the camera
  }
  if (!up_sum.allFinite() || up_sum.norm() < 1e-6) return frame;
  const Eigen::Vector3d up = up_sum.normalized();
  if (up.y() >= std::cos(M_PI / 4)) return frame;  // upright enough: keep +Y
  Eigen::Vector3d front = back_sum - back_sum.dot(up) * up;
  if (!front.allFinite() || front.norm() < 1e-6) {  // cameras looking straight down or up
    front = std::abs(up.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitZ();
    front -= front.dot(up) * up;
  }
  front.normalize();
  frame.up = up.cast<float>();
  frame.front = front.cast<float>();
  frame.side = up.cross(front).cast<float>();  // right-handed like (X, Y, Z) = (side, up, front)
  return frame;
}

Eigen::Vector3f OrbitEyeDirection(const OrbitFrame& frame, float yaw, float pitch) {
  return std::cos(pitch) * std::sin(yaw) * frame.side + std::sin(pitch) * frame.up +
         std::cos(pitch) * std::cos(yaw) * frame.front;
}

Eigen::Vector3f OrbitScreenRight(const OrbitFrame& frame, float yaw) {
  return std::cos(yaw) * frame.side - std::sin(yaw) * frame.front;
}

Eigen::Vector3f OrbitScreenUp(const OrbitFrame& frame, float yaw, float pitch) {
  return -std::sin(pitch) * std::sin(yaw) * frame.side + std::cos(pitch) * frame.up -
         std::sin(pitch) * std::cos(yaw) * frame.front;
}

}  // namespace fresco
