// Similarity transforms (scale, rotation, translation) between two frames, and their robust
// estimation from corresponding points: COLMAP's reconstruction frame is arbitrary, so it is
// brought into the project's world by `world_from_colmap` (x_world = s R x_colmap + t).
//
// EstimateSimilarity: least squares (Umeyama, Eigen::umeyama) over all pairs.
// EstimateSimilarityRobust: RANSAC over minimal sets of 3 pairs, then a refit on the inliers
// (repeated until the inlier set stops changing), so outlier pairs (wrong poses) do not bend it.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"

namespace fresco {

struct Sim3d {
  double scale = 1.0;
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  // x_b = s R x_a + t
  Eigen::Vector3d operator*(const Eigen::Vector3d& point_in_a) const {
    return scale * (rotation * point_in_a) + translation;
  }
  Sim3d Inverse() const;
  // For `this` = world_from_colmap and a COLMAP cam_from_colmap: the camera's
  // cam_from_world in metric world units (the camera centre maps through `this`, the
  // orientation is composed with the inverse rotation).
  Rigid3d TransformPose(const Rigid3d& cam_from_colmap) const;
};

// Least-squares similarity dst ~ s R src + t. `src`, `dst`: (N) points, N >= 3, not all
// collinear. Error (naming `what`) for too few or degenerate points.
Status EstimateSimilarity(const std::vector<Eigen::Vector3d>& src,
                          const std::vector<Eigen::Vector3d>& dst, const std::string& what,
                          Sim3d* dst_from_src);

struct RobustSimilarityOptions {
  // A pair is an inlier when |dst - T(src)| is below this, in dst units (metres). Must be > 0.
  double inlier_threshold = 0.05;
  int iterations = 500;  // RANSAC minimal-set trials
  unsigned seed = 1;     // random generator seed (results are deterministic)
};

struct RobustSimilarityResult {
  Sim3d dst_from_src;
  std::vector<bool> inliers;  // per pair
  int num_inliers = 0;
  double rms_inlier_error = 0.0;  // dst units
};

// RANSAC + refit (see above). Error when fewer than 3 pairs, or no non-degenerate minimal set
// with >= 3 inliers is found.
Status EstimateSimilarityRobust(const std::vector<Eigen::Vector3d>& src,
                                const std::vector<Eigen::Vector3d>& dst,
                                const RobustSimilarityOptions& options, const std::string& what,
                                RobustSimilarityResult* result);

}  // namespace fresco
