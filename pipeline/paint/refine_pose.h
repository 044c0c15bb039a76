// Refinement through the pose: the 2D matches that the refinement stage finds between each warped
// buffer and what the buffer holds (refine_alignment.h) all come from one frame, whose pose error
// is one rigid motion. So instead of one homography per buffer, fitted to that buffer's matches
// alone (and extrapolated over whatever part of it the buffer has not painted yet), one correction
// of the camera pose is fitted to the matches of every buffer together, and each buffer's
// correction is derived from it. Buffers the frame is the first to see get it too.
//
// A match says: the warped texel p (sampled from frame pixel u = project(pose * X(p))) shows
// what the buffer holds at texel q, i.e. model point X(q). The correction `delta` (camera
// frame, applied on the left: corrected cam_from_local = delta * given) minimizes the robust
// reprojection error of X(q) against u. Models, chosen per frame by BIC like the 2D motion
// models: none, rotation (3 parameters: what a tracker's jitter mostly is), rotation and
// translation (6).
//
// Coordinates: warped texel (column, row), as in refine_alignment.h; plane points from the
// buffer's plane frame (base_buffer.h), local coordinates.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "pipeline/core/camera.h"
#include "pipeline/core/project.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/paint/base_buffer.h"
#include "pipeline/paint/refine_alignment.h"

namespace fresco {

struct PoseMatch {
  Eigen::Vector3d point_local;  // X(q): what the buffer holds there, local coordinates
  Eigen::Vector2d pixel;        // u: the frame pixel the warped texel was sampled from
};

struct PoseCorrection {
  bool applied = false;
  std::string fallback;          // why not, when not
  std::string model = "none";    // "none" | "rotation" | "rotation+translation"
  Rigid3d delta;                 // corrected cam_from_local = delta * given
  int matches = 0, inliers = 0;  // inliers: within 3 x refine.ransac_px after the fit
  double residual_before_px = 0, residual_after_px = 0;  // RMS over the inliers, pixels
  std::map<std::string, double> bic;
};

// The plane point of warped texel `p` (column, row) of `buffer`, local coordinates.
Eigen::Vector3d BufferPlanePoint(const BaseBuffer& buffer, const Eigen::Vector2d& p);

// Appends the estimate's inlier matches as pose matches (given: the pose the frame was warped with).
void AppendPoseMatches(const BaseBuffer& buffer, const Camera& camera, const Rigid3d& given,
                       const RefineEstimate& estimate, std::vector<PoseMatch>* matches);

// The pixel of `point_cam` after a small motion (rotation r, translation t; left-multiplied)
// and its 2x6 Jacobian with respect to (r, t) at zero. False when it does not project.
bool PixelJacobian(const Camera& camera, const Eigen::Vector3d& point_cam, Eigen::Vector2d* pixel,
                   Eigen::Matrix<double, 2, 6>* jacobian);

PoseCorrection EstimatePoseCorrection(const std::vector<PoseMatch>& matches, const Camera& camera,
                                      const Rigid3d& given, const RefineOptions& options);

// The 2D correction of `buffer` (buffer_from_warped, as RefineEstimate's) that warping with
// `corrected` instead of `given` amounts to, fitted over `within` (warped texels). False
// when the plane is seen edge-on or the points do not project.
bool BufferCorrectionFromPose(const BaseBuffer& buffer, const Camera& camera,
                              const Rigid3d& given, const Rigid3d& corrected,
                              const cv::Rect& within, cv::Matx33d* buffer_from_warped);

}  // namespace fresco
