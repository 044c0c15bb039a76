// Rigid transforms in double precision. Naming follows the algebra: `cam_from_world` maps a
// point in world coordinates to camera coordinates, and `c_from_b * b_from_a` is `c_from_a`.
// Camera frame: x right, y down, z forward. Units: metres.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace fresco {

struct Rigid3d {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();  // unit quaternion
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Rigid3d() = default;
  Rigid3d(const Eigen::Quaterniond& q, const Eigen::Vector3d& t) : rotation(q), translation(t) {}

  // x_b = R x_a + t
  Eigen::Vector3d operator*(const Eigen::Vector3d& point_in_a) const {
    return rotation * point_in_a + translation;
  }
  Rigid3d operator*(const Rigid3d& a_from_x) const {
    return Rigid3d(rotation * a_from_x.rotation, rotation * a_from_x.translation + translation);
  }
  Rigid3d Inverse() const {
    const Eigen::Quaterniond q_inv = rotation.conjugate();
    return Rigid3d(q_inv, -(q_inv * translation));
  }
  Eigen::Matrix3d RotationMatrix() const { return rotation.toRotationMatrix(); }
  Eigen::Matrix<double, 3, 4> Matrix3x4() const {
    Eigen::Matrix<double, 3, 4> m;
    m.leftCols<3>() = RotationMatrix();
    m.col(3) = translation;
    return m;
  }
  // For a cam_from_world transform: the camera centre in world coordinates.
  Eigen::Vector3d Centre() const { return -(rotation.conjugate() * translation); }

  static Rigid3d FromMatrix(const Eigen::Matrix3d& rotation_matrix, const Eigen::Vector3d& t) {
    return Rigid3d(Eigen::Quaterniond(rotation_matrix).normalized(), t);
  }
  // Axis-angle (Rodrigues) vector: direction = axis, norm = angle in radians (mrcal's `r`).
  static Eigen::Quaterniond QuaternionFromAxisAngle(const Eigen::Vector3d& r) {
    const double angle = r.norm();
    if (angle < 1e-300) return Eigen::Quaterniond::Identity();
    return Eigen::Quaterniond(Eigen::AngleAxisd(angle, r / angle));
  }
  static Eigen::Vector3d AxisAngleFromQuaternion(const Eigen::Quaterniond& q) {
    Eigen::AngleAxisd aa(q.normalized());
    return aa.axis() * aa.angle();
  }
  // mrcal's rt: r (Rodrigues, 3) then t (3).
  static Rigid3d FromRt(const double rt[6]) {
    return Rigid3d(QuaternionFromAxisAngle(Eigen::Vector3d(rt[0], rt[1], rt[2])),
                   Eigen::Vector3d(rt[3], rt[4], rt[5]));
  }
  void ToRt(double rt[6]) const {
    const Eigen::Vector3d r = AxisAngleFromQuaternion(rotation);
    for (int i = 0; i < 3; ++i) rt[i] = r[i], rt[3 + i] = translation[i];
  }
  bool AllFinite() const {
    return rotation.coeffs().allFinite() && translation.allFinite();
  }
};

// Angle between two rotations, degrees.
inline double RotationDifferenceDeg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return Eigen::AngleAxisd((a.conjugate() * b).normalized()).angle() * 180.0 / M_PI;
}

}  // namespace fresco
