#include "pipeline/poses/pose_alignment.h"

#include <algorithm>
#include <cmath>

#include <Eigen/SVD>

namespace fresco {
namespace {

// The rotation nearest (Frobenius) to the mean of `rotations`: the chordal L2 mean.
Eigen::Matrix3d ChordalMean(const std::vector<Eigen::Matrix3d>& rotations) {
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (const Eigen::Matrix3d& r : rotations) sum += r;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sum, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

}  // namespace

Status PoseAlignmentOptions::Check() const {
  if (!(inlier_position_m > 0)) return Status::Error("inlier_position_m: must be > 0");
  if (!(inlier_rotation_deg > 0)) return Status::Error("inlier_rotation_deg: must be > 0");
  if (iterations < 1) return Status::Error("iterations: must be >= 1");
  if (!(adaptive_factor >= 0)) return Status::Error("adaptive_factor: must be >= 0");
  return Status::Ok();
}

PoseError ComparePose(const PosePair& pair, const Sim3d& world_from_colmap) {
  const Rigid3d aligned = world_from_colmap.TransformPose(pair.colmap_cam_from_colmap);
  PoseError error;
  error.rotation_deg = RotationDifferenceDeg(aligned.rotation, pair.given_cam_from_world.rotation);
  error.position_m = (aligned.Centre() - pair.given_cam_from_world.Centre()).norm();
  return error;
}

Status AlignColmapToPoses(const std::vector<PosePair>& pairs, const PoseAlignmentOptions& options,
                          PoseAlignment* alignment) {
  FRESCO_RETURN_IF_ERROR(options.Check());
  const int n = static_cast<int>(pairs.size());
  std::vector<Eigen::Vector3d> colmap_centres, given_centres;
  for (const PosePair& p : pairs) {
    colmap_centres.push_back(p.colmap_cam_from_colmap.Centre());
    given_centres.push_back(p.given_cam_from_world.Centre());
  }
  RobustSimilarityOptions robust;
  robust.inlier_threshold = options.inlier_position_m;
  robust.iterations = options.iterations;
  robust.seed = options.seed;
  RobustSimilarityResult fit;
  FRESCO_RETURN_IF_ERROR(EstimateSimilarityRobust(colmap_centres, given_centres, robust,
                                                  "camera centres (COLMAP to given poses)", &fit));
  Sim3d world_from_colmap = fit.dst_from_src;
  std::vector<bool> inliers = fit.inliers;

  // Each frame's own estimate of world_from_colmap's rotation: world_from_cam (given) *
  // cam_from_colmap (COLMAP).
  std::vector<Eigen::Matrix3d> frame_rotation(n);
  for (int i = 0; i < n; ++i) {
    frame_rotation[i] = pairs[i].given_cam_from_world.RotationMatrix().transpose() *
                        pairs[i].colmap_cam_from_colmap.RotationMatrix();
  }
  // Refits rotation (chordal mean), then scale and translation, on the inliers, and
  // re-selects the inliers within the thresholds, until they stop changing.
  auto refine = [&](double position_m, double rotation_deg) {
    for (int round = 0; round < 3; ++round) {
      std::vector<Eigen::Matrix3d> used;
      for (int i = 0; i < n; ++i) {
        if (inliers[i]) used.push_back(frame_rotation[i]);
      }
      if (used.size() < 3) break;
      const Eigen::Matrix3d rotation = ChordalMean(used);
      // Scale and translation for this rotation: least squares over the inliers.
      Eigen::Vector3d mean_c = Eigen::Vector3d::Zero(), mean_g = Eigen::Vector3d::Zero();
      int count = 0;
      for (int i = 0; i < n; ++i) {
        if (inliers[i]) mean_c += colmap_centres[i], mean_g += given_centres[i], ++count;
      }
      mean_c /= count, mean_g /= count;
      double num = 0, den = 0;
      for (int i = 0; i < n; ++i) {
        if (!inliers[i]) continue;
        const Eigen::Vector3d c = rotation * (colmap_centres[i] - mean_c);
        num += c.dot(given_centres[i] - mean_g);
        den += c.squaredNorm();
      }
      if (!(den > 0) || !(num > 0)) break;
      Sim3d refined;
      refined.scale = num / den;
      refined.rotation = Eigen::Quaterniond(rotation).normalized();
      refined.translation = mean_g - refined.scale * (rotation * mean_c);
      std::vector<bool> next(n, false);
      int next_count = 0;
      for (int i = 0; i < n; ++i) {
        const PoseError e = ComparePose(pairs[i], refined);
        if (e.position_m < position_m && e.rotation_deg < rotation_deg) {
          next[i] = true, ++next_count;
        }
      }
      if (next_count < 3) break;
      world_from_colmap = refined;
      const bool same = next == inliers;
      inliers = next;
      if (same) break;
    }
  };
  refine(options.inlier_position_m, options.inlier_rotation_deg);
  // Tighter thresholds from the inliers' own spread, repeated while the inliers change:
  // poses off by less than the given thresholds but clearly more than the rest stop
  // bending the fit (a bent fit inflates the spread, so one round may not be enough).
  for (int round = 0; options.adaptive_factor > 0 && round < 3; ++round) {
    std::vector<double> position, rotation;
    for (int i = 0; i < n; ++i) {
      if (!inliers[i]) continue;
      const PoseError e = ComparePose(pairs[i], world_from_colmap);
      position.push_back(e.position_m);
      rotation.push_back(e.rotation_deg);
    }
    if (position.size() < 6) break;
    auto median = [](std::vector<double> v) {
      std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
      return v[v.size() / 2];
    };
    const double kFloor = 0.05;  // of the given thresholds
    const std::vector<bool> before = inliers;
    refine(std::clamp(options.adaptive_factor * median(position),
                      kFloor * options.inlier_position_m, options.inlier_position_m),
           std::clamp(options.adaptive_factor * median(rotation),
                      kFloor * options.inlier_rotation_deg, options.inlier_rotation_deg));
    if (inliers == before) break;
  }
  alignment->world_from_colmap = world_from_colmap;
  alignment->inliers = inliers;
  alignment->num_inliers = static_cast<int>(std::count(inliers.begin(), inliers.end(), true));
  return Status::Ok();
}

}  // namespace fresco
