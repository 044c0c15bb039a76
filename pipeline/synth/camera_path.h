// Camera paths for synthetic captures and the synthetic camera itself. Poses are
// cam_from_world (camera frame x right, y down, z forward; world = glTF frame, +Y up).
// Paths are smooth, deterministic functions of the seed:
//  - orbit: a circle around `target` at `radius_m`, at world height `height_m`, looking at
//    the target;
//  - walk: a straight walk from `walk_from` to `walk_to` at constant speed with a small step
//    bob, looking ahead and glancing left and right (`look_around_deg`);
//  - handheld: a hand-held camera wandering around `target` (circle of `radius_m` plus smooth
//    random wander of `wander_m`), either looking at the target or looking freely around
//    (`turns` full turns of heading over the capture), with smooth shake (`wobble_deg`);
//  - fixed: a camera mounted at `eye` looking at `target` (a surveillance camera), still
//    unless `wobble_deg` > 0 (a mast in the wind).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "pipeline/core/camera.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"

namespace fresco {

enum class CameraPathKind { kOrbit, kWalk, kHandheld, kFixed };
// "orbit" | "walk" | "handheld" | "fixed"
std::string CameraPathKindName(CameraPathKind kind);
bool CameraPathKindFromName(const std::string& name, CameraPathKind* kind);

struct CameraPathOptions {
  CameraPathKind kind = CameraPathKind::kHandheld;
  // orbit: the point looked at; handheld: the centre wandered around (and looked at when
  // `look_at_target`). World coordinates, metres.
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  double radius_m = 1.0;   // orbit radius; handheld: radius of the base circle
  double height_m = 0.0;   // orbit, handheld: world height (y) of the camera's circle
  double turns = 1.0;      // orbit: revolutions; handheld: turns of the base circle/heading
  double start_deg = 0.0;  // angle of the first position on the circle (0 = +X, 90 = +Z)
  // handheld: amplitude (RMS) of the smooth random position wander, metres.
  double wander_m = 0.2;
  // handheld / walk: RMS of the smooth random shake of the look direction, degrees.
  double wobble_deg = 4.0;
  // handheld: look at `target` (true) or look freely outwards (false, e.g. inside a room).
  bool look_at_target = true;
  // handheld (free look) and walk: mean pitch of the look direction (negative = down).
  double pitch_deg = 0.0;
  // handheld (free look): amplitude of a slow up/down sweep of the pitch (3 cycles per
  // capture), so that floors and ceilings come into view too.
  double tilt_deg = 0.0;
  // walk: from -> to at constant speed, eye height included in both points.
  Eigen::Vector3d walk_from = Eigen::Vector3d(-1, 0, 0);
  Eigen::Vector3d walk_to = Eigen::Vector3d(1, 0, 0);
  double look_around_deg = 20.0;  // walk: amplitude of the glances left/right
  double bob_m = 0.02;            // walk: vertical step bob amplitude
  // fixed: where the camera is mounted, world, metres (it looks at `target`).
  Eigen::Vector3d eye = Eigen::Vector3d(0, 0, 1);

  Status Check() const;  // message names the field
};

// cam_from_world for a camera at `eye` looking at `point` (world up = +Y), rolled by
// `roll_rad` about its optical axis. Looking straight up or down picks a stable right axis.
Rigid3d LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& point, double roll_rad = 0.0);
// cam_from_world for a camera at `eye` looking along `direction` (any length > 0).
Rigid3d LookAlong(const Eigen::Vector3d& eye, const Eigen::Vector3d& direction,
                  double roll_rad = 0.0);

// `frames` poses (cam_from_world) along the path, deterministic for `seed`.
std::vector<Rigid3d> MakeCameraPath(const CameraPathOptions& options, int frames, unsigned seed);

// A synthetic camera: `hfov_deg` gives fx = fy = (width/2) / tan(hfov/2), the principal point
// is the image centre ((width-1)/2, (height-1)/2). Lenses other than pinhole get mild,
// realistic barrel distortion (k1 = -0.05, k2 = 0.01, small tangential terms; monotonic
// out to normalized radius 2, i.e. beyond a 120 degree field). Supports kPinhole, kOpenCV4,
// kOpenCV5, kOpenCV8.
Status MakeSynthCamera(LensModel lens, int width, int height, double hfov_deg, Camera* camera);

}  // namespace fresco
