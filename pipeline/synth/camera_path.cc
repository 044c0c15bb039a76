#include "pipeline/synth/camera_path.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "pipeline/synth/random.h"

namespace fresco {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
// Smooth noise runs on "frames / 60" time: frequencies are in cycles per 60 frames (two
// seconds at 30 fps), so the motion's character does not depend on the capture's length.
constexpr double kNoiseFramesPerUnit = 60.0;

// Unit direction with yaw measured in the XZ plane from +X towards +Z, pitch up from it.
Eigen::Vector3d DirectionFromYawPitch(double yaw_rad, double pitch_rad) {
  return Eigen::Vector3d(std::cos(pitch_rad) * std::cos(yaw_rad), std::sin(pitch_rad),
                         std::cos(pitch_rad) * std::sin(yaw_rad));
}

void YawPitchFromDirection(const Eigen::Vector3d& d, double* yaw_rad, double* pitch_rad) {
  const Eigen::Vector3d n = d.normalized();
  *yaw_rad = std::atan2(n.z(), n.x());
  *pitch_rad = std::asin(std::clamp(n.y(), -1.0, 1.0));
}

bool FiniteVector(const Eigen::Vector3d& v) { return v.allFinite(); }

}  // namespace

std::string CameraPathKindName(CameraPathKind kind) {
  switch (kind) {
    case CameraPathKind::kOrbit:
      return "orbit";
    case CameraPathKind::kWalk:
      return "walk";
    case CameraPathKind::kHandheld:
      return "handheld";
    case CameraPathKind::kFixed:
      return "fixed";
  }
  return "?";
}

bool CameraPathKindFromName(const std::string& name, CameraPathKind* kind) {
  for (CameraPathKind k : {CameraPathKind::kOrbit, CameraPathKind::kWalk, CameraPathKind::kHandheld,
                           CameraPathKind::kFixed}) {
    if (name == CameraPathKindName(k)) {
      *kind = k;
      return true;
    }
  }
  return false;
}

Status CameraPathOptions::Check() const {
  if (!FiniteVector(target)) return Status::Error("path.target: not finite");
  if (!FiniteVector(walk_from)) return Status::Error("path.walk_from: not finite");
  if (!FiniteVector(walk_to)) return Status::Error("path.walk_to: not finite");
  if (!FiniteVector(eye)) return Status::Error("path.eye: not finite");
  const double values[] = {radius_m,   height_m,  turns,    start_deg,       wander_m,
                           wobble_deg, pitch_deg, tilt_deg, look_around_deg, bob_m};
  for (double v : values) {
    if (!std::isfinite(v)) return Status::Error("path: a setting is not finite");
  }
  if (radius_m < 0) return Status::Error("path.radius_m: must be >= 0");
  if (wander_m < 0) return Status::Error("path.wander_m: must be >= 0");
  if (wobble_deg < 0 || wobble_deg > 45)
    return Status::Error("path.wobble_deg: must be in [0, 45]");
  if (std::abs(pitch_deg) > 85) return Status::Error("path.pitch_deg: must be in [-85, 85]");
  if (tilt_deg < 0 || tilt_deg > 85) return Status::Error("path.tilt_deg: must be in [0, 85]");
  if (kind == CameraPathKind::kOrbit && radius_m <= 0 && std::abs(height_m - target.y()) <= 0) {
    return Status::Error("path.radius_m: an orbit needs radius_m > 0 (or a height off the target)");
  }
  if (kind == CameraPathKind::kWalk && (walk_to - walk_from).norm() < 1e-6) {
    return Status::Error("path.walk_to: must differ from path.walk_from");
  }
  if (kind == CameraPathKind::kFixed && (target - eye).norm() < 1e-6) {
    return Status::Error("path.eye: must differ from path.target (the point looked at)");
  }
  return Status::Ok();
}

Rigid3d LookAlong(const Eigen::Vector3d& eye, const Eigen::Vector3d& direction, double roll_rad) {
  const Eigen::Vector3d z = direction.normalized();
  Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitY());
  if (x.norm() < 1e-9) x = Eigen::Vector3d::UnitX();  // looking straight up or down
  x.normalize();
  Eigen::Vector3d y = z.cross(x);
  if (roll_rad != 0.0) {
    const double c = std::cos(roll_rad), s = std::sin(roll_rad);
    const Eigen::Vector3d xr = c * x + s * y, yr = -s * x + c * y;
    x = xr;
    y = yr;
  }
  Eigen::Matrix3d world_from_cam;
  world_from_cam.col(0) = x;
  world_from_cam.col(1) = y;
  world_from_cam.col(2) = z;
  const Eigen::Matrix3d cam_from_world = world_from_cam.transpose();
  return Rigid3d::FromMatrix(cam_from_world, -(cam_from_world * eye));
}

Rigid3d LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& point, double roll_rad) {
  Eigen::Vector3d d = point - eye;
  if (d.norm() < 1e-12) d = -Eigen::Vector3d::UnitZ();
  return LookAlong(eye, d, roll_rad);
}

std::vector<Rigid3d> MakeCameraPath(const CameraPathOptions& o, int frames, unsigned seed) {
  std::vector<Rigid3d> poses;
  if (frames <= 0) return poses;
  poses.reserve(frames);
  SynthRandom random(seed, 11);
  // Independent smooth signals for position wander and look shake.
  const SmoothNoise wander_x(&random, 0.3, 1.2), wander_y(&random, 0.3, 1.2),
      wander_z(&random, 0.3, 1.2);
  const SmoothNoise shake_yaw(&random, 0.5, 2.5), shake_pitch(&random, 0.5, 2.5),
      shake_roll(&random, 0.5, 2.5);
  const SmoothNoise glance(&random, 0.15, 0.5, 2);
  const double tilt_phase = random.Uniform(0.0, 2.0 * M_PI);
  const double wobble = o.wobble_deg * kDegToRad;

  for (int i = 0; i < frames; ++i) {
    const double t = static_cast<double>(i) / frames;               // capture fraction
    const double u = static_cast<double>(i) / kNoiseFramesPerUnit;  // noise time
    const double theta = o.start_deg * kDegToRad + 2.0 * M_PI * o.turns * t;
    switch (o.kind) {
      case CameraPathKind::kOrbit: {
        const Eigen::Vector3d eye(o.target.x() + o.radius_m * std::cos(theta), o.height_m,
                                  o.target.z() + o.radius_m * std::sin(theta));
        poses.push_back(LookAt(eye, o.target));
        break;
      }
      case CameraPathKind::kHandheld: {
        const Eigen::Vector3d eye =
            Eigen::Vector3d(o.target.x() + o.radius_m * std::cos(theta), o.height_m,
                            o.target.z() + o.radius_m * std::sin(theta)) +
            o.wander_m * Eigen::Vector3d(wander_x(u), 0.3 * wander_y(u), wander_z(u));
        double yaw = theta,
               pitch =
                   (o.pitch_deg + o.tilt_deg * std::sin(6.0 * M_PI * t + tilt_phase)) * kDegToRad;
        if (o.look_at_target) YawPitchFromDirection(o.target - eye, &yaw, &pitch);
        yaw += wobble * shake_yaw(u);
        pitch = std::clamp(pitch + wobble * shake_pitch(u), -1.5, 1.5);
        poses.push_back(
            LookAlong(eye, DirectionFromYawPitch(yaw, pitch), 0.4 * wobble * shake_roll(u)));
        break;
      }
      case CameraPathKind::kWalk: {
        const double s = frames > 1 ? static_cast<double>(i) / (frames - 1) : 0.0;
        const Eigen::Vector3d travel = o.walk_to - o.walk_from;
        const double distance = s * travel.norm();
        const Eigen::Vector3d eye =
            o.walk_from + s * travel +
            Eigen::Vector3d(0, o.bob_m * std::sin(2.0 * M_PI * distance / 1.4), 0);
        double yaw = 0.0, pitch = 0.0;
        YawPitchFromDirection(travel, &yaw, &pitch);
        yaw += o.look_around_deg * kDegToRad * glance(u) + wobble * shake_yaw(u);
        pitch = std::clamp(o.pitch_deg * kDegToRad + wobble * shake_pitch(u), -1.5, 1.5);
        poses.push_back(
            LookAlong(eye, DirectionFromYawPitch(yaw, pitch), 0.4 * wobble * shake_roll(u)));
        break;
      }
      case CameraPathKind::kFixed: {
        if (wobble == 0.0) {
          poses.push_back(LookAt(o.eye, o.target));
          break;
        }
        double yaw = 0.0, pitch = 0.0;
        YawPitchFromDirection(o.target - o.eye, &yaw, &pitch);
        yaw += wobble * shake_yaw(u);
        pitch = std::clamp(pitch + wobble * shake_pitch(u), -1.5, 1.5);
        poses.push_back(
            LookAlong(o.eye, DirectionFromYawPitch(yaw, pitch), 0.4 * wobble * shake_roll(u)));
        break;
      }
    }
  }
  return poses;
}

Status MakeSynthCamera(LensModel lens, int width, int height, double hfov_deg, Camera* camera) {
  if (width < 8 || height < 8 || width > 16384 || height > 16384) {
    return Status::Error("size: width and height must be in [8, 16384] pixels");
  }
  if (!std::isfinite(hfov_deg) || hfov_deg < 5.0 || hfov_deg > 150.0) {
    return Status::Error("hfov_deg: must be in [5, 150] degrees");
  }
  const double f = 0.5 * width / std::tan(0.5 * hfov_deg * kDegToRad);
  std::vector<double> params = {f, f, 0.5 * (width - 1), 0.5 * (height - 1)};
  // Mild barrel distortion: k1 k2 p1 p2 [k3 [k4 k5 k6]].
  switch (lens) {
    case LensModel::kPinhole:
      break;
    case LensModel::kOpenCV4:
      params.insert(params.end(), {-0.05, 0.01, 0.0004, -0.0003});
      break;
    case LensModel::kOpenCV5:
      params.insert(params.end(), {-0.05, 0.01, 0.0004, -0.0003, -0.001});
      break;
    case LensModel::kOpenCV8:
      params.insert(params.end(), {-0.05, 0.01, 0.0004, -0.0003, -0.001, 0.01, 0.0, 0.0});
      break;
    default:
      return Status::Error("lens: synthetic cameras support pinhole, opencv4, opencv5, opencv8");
  }
  const Camera c = Camera::FromParams(lens, width, height, params);
  *camera = c;
  return Status::Ok();
}

}  // namespace fresco
