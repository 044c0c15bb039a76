// Bootstrapping poses from COLMAP (`fresco poses bootstrap`): COLMAP's reconstruction is
// placed in the project's world by a similarity from either
//  - the project's given poses (robust, pose_alignment.h: rough or partly wrong poses are
//    enough), or
//  - >= 3 control points: known world points observed in >= 2 images each, triangulated in
//    COLMAP's frame (linear least squares on the undistorted rays) and aligned by Umeyama.
// The result is one cam_from_world per registered frame, plus COLMAP's points in the world.
//
// Control-point file: one point per line, '#' comments:
//   NAME X Y Z  IMAGE U V  [IMAGE U V ...]
// X Y Z in the world (metres); U V in pixels with (0,0) the centre of the top-left pixel.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "pipeline/core/camera.h"
#include "pipeline/core/poses.h"
#include "pipeline/core/status.h"
#include "pipeline/poses/similarity.h"

namespace fresco {

struct ControlObservation {
  std::string image;
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
};
struct ControlPoint {
  std::string name;
  Eigen::Vector3d point_in_world = Eigen::Vector3d::Zero();
  std::vector<ControlObservation> observations;
};

Status ReadControlPoints(const std::string& path, std::vector<ControlPoint>* points);

// Triangulates each control point from its observations in the registered COLMAP images
// (matched by image name) and fits world_from_colmap. Errors name the file and point.
struct ControlPointFit {
  Sim3d world_from_colmap;
  std::vector<double> residual_m;  // per point: |world - aligned triangulation|
};
Status AlignWithControlPoints(const std::vector<ControlPoint>& points, const std::string& what,
                              const ColmapModel& model, const Camera& camera, ControlPointFit* fit);

// COLMAP's model moved into the world: cam_from_world poses (names and ids kept), points.
ColmapModel TransformModel(const ColmapModel& model, const Sim3d& world_from_colmap);

}  // namespace fresco
