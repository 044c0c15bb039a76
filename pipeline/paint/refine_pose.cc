#include "pipeline/paint/refine_pose.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>
#include <opencv2/calib3d.hpp>

namespace fresco {
namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// Residuals of every match under `delta` (NaN where the point does not project).
std::vector<Eigen::Vector2d> Residuals(const std::vector<PoseMatch>& matches, const Camera& camera,
                                       const Rigid3d& cam_from_local) {
  std::vector<Eigen::Vector2d> r(matches.size());
  for (size_t j = 0; j < matches.size(); ++j) {
    Eigen::Vector2d pixel;
    r[j] = camera.Project(cam_from_local * matches[j].point_local, &pixel)
               ? Eigen::Vector2d(pixel - matches[j].pixel)
               : Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  return r;
}

double HuberCost(const std::vector<Eigen::Vector2d>& residuals, double k) {
  double cost = 0;
  for (const Eigen::Vector2d& r : residuals) {
    if (!r.allFinite()) continue;
    const double n = r.norm();
    cost += n <= k ? 0.5 * n * n : k * (n - 0.5 * k);
  }
  return cost;
}

// Levenberg-Marquardt on the Huber cost over the first `params` of (r, t).
Rigid3d FitDelta(const std::vector<PoseMatch>& matches, const Camera& camera, const Rigid3d& given,
                 int params, double huber_px) {
  Rigid3d delta;
  double cost = HuberCost(Residuals(matches, camera, given), huber_px);
  double lambda = 1e-4;
  for (int iteration = 0; iteration < 20; ++iteration) {
    const Rigid3d pose = delta * given;
    Eigen::Matrix<double, 6, 6> normal = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> gradient = Eigen::Matrix<double, 6, 1>::Zero();
    for (const PoseMatch& m : matches) {
      Eigen::Vector2d pixel;
      Eigen::Matrix<double, 2, 6> J;
      if (!PixelJacobian(camera, pose * m.point_local, &pixel, &J)) continue;
      const Eigen::Vector2d r = pixel - m.pixel;
      const double n = r.norm();
      const double w = n <= huber_px ? 1.0 : huber_px / n;
      normal += w * J.transpose() * J;
      gradient += w * J.transpose() * r;
    }
    Eigen::MatrixXd A = normal.topLeftCorner(params, params);
    A.diagonal() *= 1 + lambda;
    const Eigen::VectorXd step = A.ldlt().solve(-gradient.head(params));
    if (!step.allFinite()) break;
    Eigen::Vector3d dt = Eigen::Vector3d::Zero();
    if (params == 6) dt = step.tail<3>();
    const Rigid3d increment(Rigid3d::QuaternionFromAxisAngle(step.head<3>()), dt);
    const Rigid3d candidate = increment * delta;
    const double candidate_cost =
        HuberCost(Residuals(matches, camera, candidate * given), huber_px);
    if (candidate_cost <= cost) {
      delta = candidate;
      lambda = std::max(1e-8, lambda * 0.1);
      const bool converged = cost - candidate_cost < 1e-10 * (1 + cost) || step.norm() < 1e-12;
      cost = candidate_cost;
      if (converged) break;
    } else {
      lambda *= 10;
      if (lambda > 1e6) break;
    }
  }
  return delta;
}

}  // namespace

Eigen::Vector3d BufferPlanePoint(const BaseBuffer& buffer, const Eigen::Vector2d& p) {
  return buffer.origin + (p.x() + 0.5) * buffer.texel_size_m * buffer.axis_u +
         (p.y() + 0.5) * buffer.texel_size_m * buffer.axis_v;
}

void AppendPoseMatches(const BaseBuffer& buffer, const Camera& camera, const Rigid3d& given,
                       const RefineEstimate& estimate, std::vector<PoseMatch>* matches) {
  for (size_t i = 0; i < estimate.from.size(); ++i) {
    if (!estimate.inlier[i]) continue;
    const Eigen::Vector2d p(estimate.from[i].x, estimate.from[i].y);
    const Eigen::Vector2d q(estimate.to[i].x, estimate.to[i].y);
    PoseMatch m;
    if (!camera.Project(given * BufferPlanePoint(buffer, p), &m.pixel)) continue;
    m.point_local = BufferPlanePoint(buffer, q);
    matches->push_back(m);
  }
}

bool PixelJacobian(const Camera& camera, const Eigen::Vector3d& point_cam, Eigen::Vector2d* pixel,
                   Eigen::Matrix<double, 2, 6>* jacobian) {
  Eigen::Matrix<double, 2, 3> d_pixel_d_point;
  if (!camera.ProjectWithJacobian(point_cam, pixel, &d_pixel_d_point)) return false;
  // point' = exp(r) point + t: d point'/dr = -[point]x, d point'/dt = I.
  jacobian->leftCols<3>() = -d_pixel_d_point * Skew(point_cam);
  jacobian->rightCols<3>() = d_pixel_d_point;
  return true;
}

PoseCorrection EstimatePoseCorrection(const std::vector<PoseMatch>& matches, const Camera& camera,
                                      const Rigid3d& given, const RefineOptions& options) {
  PoseCorrection c;
  c.matches = static_cast<int>(matches.size());
  if (c.matches < std::max(options.min_inliers, 6)) {
    c.fallback = "too few matches for a pose";
    return c;
  }
  const double huber = options.ransac_px;
  // The matches every model is judged on: those the richest (Huber) fit explains. Huber
  // still feels gross outliers a little, so the models are then fitted to these alone.
  const std::vector<Eigen::Vector2d> r_full =
      Residuals(matches, camera, FitDelta(matches, camera, given, 6, huber) * given);
  std::vector<size_t> kept;
  std::vector<PoseMatch> inlier_matches;
  for (size_t j = 0; j < matches.size(); ++j) {
    if (r_full[j].allFinite() && r_full[j].norm() < 3 * huber) {
      kept.push_back(j);
      inlier_matches.push_back(matches[j]);
    }
  }
  c.inliers = static_cast<int>(kept.size());
  if (c.inliers < std::max(options.min_inliers, 6)) {
    c.fallback = "too few matches agree on a pose";
    return c;
  }
  const Rigid3d rotation = FitDelta(inlier_matches, camera, given, 3, huber);
  const Rigid3d full = FitDelta(inlier_matches, camera, given, 6, huber);
  const double n = 2.0 * c.inliers;
  struct Candidate {
    const char* name;
    Rigid3d delta;
    int params;
    double rss = 0;
  };
  Candidate candidates[] = {{"none", Rigid3d(), 0}, {"rotation", rotation, 3},
                            {"rotation+translation", full, 6}};
  const Candidate* best = nullptr;
  double best_bic = std::numeric_limits<double>::infinity();
  for (Candidate& candidate : candidates) {
    const std::vector<Eigen::Vector2d> r = Residuals(matches, camera, candidate.delta * given);
    for (size_t j : kept) {
      const double e = r[j].allFinite() ? r[j].norm() : 3 * huber;
      candidate.rss += std::min(e, 3 * huber) * std::min(e, 3 * huber);
    }
    // Floor: sub-pixel matching does not resolve below ~0.01 texel.
    const double bic = n * std::log(std::max(candidate.rss, 1e-4 * n) / n) +
                       candidate.params * std::log(n);
    c.bic[candidate.name] = bic;
    if (bic < best_bic) best_bic = bic, best = &candidate;
  }
  c.residual_before_px = std::sqrt(candidates[0].rss / c.inliers);
  c.residual_after_px = std::sqrt(best->rss / c.inliers);
  c.model = best->name;
  c.delta = best->delta;
  if (best->params == 0) {
    c.fallback = "the matches need no pose correction";
    return c;
  }
  // A correction larger than the search window was not measured by the matches.
  const double angle_px = Rigid3d::AxisAngleFromQuaternion(c.delta.rotation).norm() *
                          std::max(camera.fx, camera.fy);
  if (!(angle_px <= 2.0 * options.search_px)) {
    c.fallback = "pose correction larger than the search window";
    c.delta = Rigid3d();
    return c;
  }
  c.applied = true;
  return c;
}

bool BufferCorrectionFromPose(const BaseBuffer& buffer, const Camera& camera,
                              const Rigid3d& given, const Rigid3d& corrected,
                              const cv::Rect& within, cv::Matx33d* buffer_from_warped) {
  if (within.empty()) return false;
  const Eigen::Vector3d& normal = buffer.normal;
  const Eigen::Vector3d centre = given.Centre();
  const Eigen::Quaterniond local_from_cam = given.rotation.conjugate();
  constexpr int kGrid = 5;
  std::vector<cv::Point2f> from, to;
  for (int gy = 0; gy < kGrid; ++gy) {
    for (int gx = 0; gx < kGrid; ++gx) {
      // q: a buffer texel; where does the warp with the given pose see what `corrected` puts there?
      const Eigen::Vector2d q(within.x + (within.width - 1) * gx / (kGrid - 1.0),
                              within.y + (within.height - 1) * gy / (kGrid - 1.0));
      Eigen::Vector2d pixel, normalized;
      if (!camera.Project(corrected * BufferPlanePoint(buffer, q), &pixel) ||
          !camera.Unproject(pixel, &normalized))
        continue;
      const Eigen::Vector3d ray = local_from_cam * Eigen::Vector3d(normalized.x(), normalized.y(), 1);
      const double along = normal.dot(ray);
      if (std::abs(along) < 1e-6 * ray.norm()) continue;
      const double depth = normal.dot(buffer.origin - centre) / along;
      if (!(depth > 0)) continue;
      const Eigen::Vector2d p = buffer.TexelCoords(centre + depth * ray) - Eigen::Vector2d(0.5, 0.5);
      from.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
      to.emplace_back(static_cast<float>(q.x()), static_cast<float>(q.y()));
    }
  }
  if (from.size() < 8) return false;
  const cv::Mat H = cv::findHomography(from, to, 0);
  if (H.empty()) return false;
  *buffer_from_warped = cv::Matx33d(H);
  return true;
}

}  // namespace fresco
