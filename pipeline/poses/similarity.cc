#include "pipeline/poses/similarity.h"

#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <Eigen/SVD>

namespace fresco {
namespace {

Eigen::Matrix3Xd ToMatrix(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Matrix3Xd m(3, points.size());
  for (size_t i = 0; i < points.size(); ++i) m.col(i) = points[i];
  return m;
}

// True when the points span at least a plane (not all (nearly) on one line or one point),
// relative to their spread.
bool NonCollinear(const Eigen::Matrix3Xd& points) {
  const Eigen::Vector3d mean = points.rowwise().mean();
  const Eigen::Matrix3Xd centred = points.colwise() - mean;
  const Eigen::JacobiSVD<Eigen::Matrix3Xd> svd(centred);
  const Eigen::Vector3d s = svd.singularValues();
  return s[0] > 0 && s[1] > 1e-6 * s[0];
}

Status FitMatrices(const Eigen::Matrix3Xd& src, const Eigen::Matrix3Xd& dst,
                   const std::string& what, Sim3d* dst_from_src) {
  if (src.cols() < 3) {
    return Status::Error(what + ": a similarity needs at least 3 point pairs, got " +
                         std::to_string(src.cols()));
  }
  if (!NonCollinear(src) || !NonCollinear(dst)) {
    return Status::Error(what +
                         ": the points are (nearly) collinear: the rotation about "
                         "their line is undetermined");
  }
  const Eigen::Matrix4d m = Eigen::umeyama(src, dst, true);
  const Eigen::Matrix3d sr = m.topLeftCorner<3, 3>();
  const double scale = std::cbrt(sr.determinant());
  if (!(scale > 0) || !std::isfinite(scale)) {
    return Status::Error(what + ": degenerate similarity (scale " + std::to_string(scale) + ")");
  }
  dst_from_src->scale = scale;
  dst_from_src->rotation = Eigen::Quaterniond(sr / scale).normalized();
  dst_from_src->translation = m.topRightCorner<3, 1>();
  return Status::Ok();
}

}  // namespace

Sim3d Sim3d::Inverse() const {
  Sim3d inverse;
  inverse.scale = 1.0 / scale;
  inverse.rotation = rotation.conjugate();
  inverse.translation = -(inverse.rotation * translation) / scale;
  return inverse;
}

Rigid3d Sim3d::TransformPose(const Rigid3d& cam_from_colmap) const {
  const Eigen::Quaterniond cam_from_world_rotation =
      (cam_from_colmap.rotation * rotation.conjugate()).normalized();
  const Eigen::Vector3d centre_in_world = (*this) * cam_from_colmap.Centre();
  return Rigid3d(cam_from_world_rotation, -(cam_from_world_rotation * centre_in_world));
}

Status EstimateSimilarity(const std::vector<Eigen::Vector3d>& src,
                          const std::vector<Eigen::Vector3d>& dst, const std::string& what,
                          Sim3d* dst_from_src) {
  if (src.size() != dst.size()) {
    return Status::Error(what + ": " + std::to_string(src.size()) + " source points but " +
                         std::to_string(dst.size()) + " destination points");
  }
  return FitMatrices(ToMatrix(src), ToMatrix(dst), what, dst_from_src);
}

Status EstimateSimilarityRobust(const std::vector<Eigen::Vector3d>& src,
                                const std::vector<Eigen::Vector3d>& dst,
                                const RobustSimilarityOptions& options, const std::string& what,
                                RobustSimilarityResult* result) {
  if (src.size() != dst.size()) {
    return Status::Error(what + ": " + std::to_string(src.size()) + " source points but " +
                         std::to_string(dst.size()) + " destination points");
  }
  if (!(options.inlier_threshold > 0)) {
    return Status::Error(what + ": inlier_threshold must be > 0");
  }
  const int n = static_cast<int>(src.size());
  if (n < 3) {
    return Status::Error(what + ": a similarity needs at least 3 point pairs, got " +
                         std::to_string(n));
  }
  const double threshold2 = options.inlier_threshold * options.inlier_threshold;
  auto inliers_of = [&](const Sim3d& t, std::vector<bool>* inliers) {
    int count = 0;
    inliers->assign(n, false);
    for (int i = 0; i < n; ++i) {
      if ((t * src[i] - dst[i]).squaredNorm() < threshold2) (*inliers)[i] = true, ++count;
    }
    return count;
  };
  auto fit_subset = [&](const std::vector<bool>& use, Sim3d* t) {
    std::vector<Eigen::Vector3d> s, d;
    for (int i = 0; i < n; ++i) {
      if (use[i]) s.push_back(src[i]), d.push_back(dst[i]);
    }
    return FitMatrices(ToMatrix(s), ToMatrix(d), what, t);
  };

  std::mt19937 rng(options.seed);
  std::uniform_int_distribution<int> pick(0, n - 1);
  Sim3d best;
  std::vector<bool> best_inliers;
  int best_count = 0;
  // All pairs first: with few outliers it is already the answer.
  {
    Sim3d t;
    std::vector<bool> inliers;
    if (fit_subset(std::vector<bool>(n, true), &t).ok()) {
      best_count = inliers_of(t, &inliers);
      best = t, best_inliers = inliers;
    }
  }
  for (int iteration = 0; iteration < options.iterations && best_count < n; ++iteration) {
    std::vector<bool> use(n, false);
    int picked = 0;
    for (int guard = 0; picked < 3 && guard < 100; ++guard) {
      const int i = pick(rng);
      if (!use[i]) use[i] = true, ++picked;
    }
    Sim3d t;
    if (picked < 3 || !fit_subset(use, &t).ok()) continue;
    std::vector<bool> inliers;
    const int count = inliers_of(t, &inliers);
    if (count > best_count) best_count = count, best = t, best_inliers = inliers;
  }
  if (best_count < 3) {
    return Status::Error(what + ": no similarity agrees with at least 3 of " + std::to_string(n) +
                         " point pairs within " + std::to_string(options.inlier_threshold));
  }
  // Refit on the inliers until the set stops changing.
  for (int round = 0; round < 10; ++round) {
    Sim3d t;
    if (!fit_subset(best_inliers, &t).ok()) break;
    std::vector<bool> inliers;
    const int count = inliers_of(t, &inliers);
    if (count < 3) break;
    const bool same = inliers == best_inliers;
    best = t, best_inliers = inliers, best_count = count;
    if (same) break;
  }
  double sum2 = 0;
  for (int i = 0; i < n; ++i) {
    if (best_inliers[i]) sum2 += (best * src[i] - dst[i]).squaredNorm();
  }
  result->dst_from_src = best;
  result->inliers = best_inliers;
  result->num_inliers = best_count;
  result->rms_inlier_error = std::sqrt(sum2 / best_count);
  return Status::Ok();
}

}  // namespace fresco
