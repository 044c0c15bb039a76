#include "calib/uncertainty.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

extern "C" {
#include <mrcal/mrcal.h>
}

namespace fresco::calib {
namespace {

double WorstDirectionStdev(const Eigen::Matrix2d& covariance) {
  const double a = covariance(0, 0), b = covariance(1, 0), c = covariance(1, 1);
  return std::sqrt(std::max(0.0, (a + c) / 2 + std::sqrt((a - c) * (a - c) / 4 + b * b)));
}

}  // namespace

bool ProjectionGradient(const SolveResult& fit, const Eigen::Vector2d& pixel, double range_m,
                        Eigen::MatrixXd* G) {
  const Eigen::MatrixXd& covariance = fit.state_covariance_per_px2;
  const int n_intrinsics = static_cast<int>(fit.intrinsics.size());
  const int n_views = static_cast<int>(fit.views.size());
  if (n_views == 0 || covariance.rows() < n_intrinsics + 6 * n_views) return false;
  mrcal_lensmodel_t model;
  if (!mrcal_lensmodel_from_name(&model, fit.lensmodel.c_str()) || model.type < 0 ||
      mrcal_lensmodel_num_params(&model) != n_intrinsics)
    return false;
  const mrcal_point2_t q{{pixel.x(), pixel.y()}};
  mrcal_point3_t v;
  if (!mrcal_unproject(&v, &q, 1, &model, fit.intrinsics.data())) return false;
  Eigen::Vector3d direction(v.x, v.y, v.z);
  if (!direction.allFinite() || direction.norm() <= 0) return false;
  direction.normalize();
  const bool at_infinity = range_m <= 0;
  const Eigen::Vector3d p_cam = at_infinity ? direction : direction * range_m;

  // dq/dp and dq/dintrinsics at the point.
  mrcal_point3_t p{{p_cam.x(), p_cam.y(), p_cam.z()}};
  mrcal_point2_t q_back;
  mrcal_point3_t dq_dp[2];
  std::vector<double> dq_dintrinsics(2 * n_intrinsics);
  if (!mrcal_project(&q_back, dq_dp, dq_dintrinsics.data(), &p, 1, &model, fit.intrinsics.data()))
    return false;
  Eigen::Matrix<double, 2, 3> dq_dpcam;
  for (int row = 0; row < 2; ++row)
    for (int k = 0; k < 3; ++k) dq_dpcam(row, k) = dq_dp[row].xyz[k];

  // G = dq/d(state): the intrinsics directly; each board pose through the mean of the point
  // mapped back from that board's frame (mrcal's "mean frames" reference).
  G->setZero(2, covariance.rows());
  for (int row = 0; row < 2; ++row)
    for (int i = 0; i < n_intrinsics; ++i) (*G)(row, i) = dq_dintrinsics[row * n_intrinsics + i];
  for (int view = 0; view < n_views; ++view) {
    const double* rt = fit.views[view].rt_cam_from_board.data();
    double p_board[3], p_back[3];
    if (at_infinity) {
      double J_r[9];  // (3,3) row-major
      mrcal_rotate_point_r_inverted(p_board, nullptr, nullptr, rt, p_cam.data());
      mrcal_rotate_point_r(p_back, J_r, nullptr, rt, p_board);
      const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> dp_dr(J_r);
      G->block(0, n_intrinsics + 6 * view, 2, 3) = dq_dpcam * dp_dr / n_views;
    } else {
      double J_rt[18];  // (3,6) row-major
      mrcal_transform_point_rt_inverted(p_board, nullptr, nullptr, rt, p_cam.data());
      mrcal_transform_point_rt(p_back, J_rt, nullptr, rt, p_board);
      const Eigen::Map<const Eigen::Matrix<double, 3, 6, Eigen::RowMajor>> dp_drt(J_rt);
      G->block(0, n_intrinsics + 6 * view, 2, 6) = dq_dpcam * dp_drt / n_views;
    }
  }
  return G->allFinite();
}

double ProjectionUncertainty_px(const SolveResult& fit, const Eigen::Vector2d& pixel,
                                double range_m, double sigma_px) {
  Eigen::MatrixXd G;
  if (!ProjectionGradient(fit, pixel, range_m, &G)) return -1;
  const Eigen::Matrix2d var =
      sigma_px * sigma_px * (G * fit.state_covariance_per_px2 * G.transpose());
  const double stdev = WorstDirectionStdev(var);
  return std::isfinite(stdev) ? stdev : -1;
}

double ExpectedProjectionDifference_px(const SolveResult& a, double sigma_a_px,
                                       const SolveResult& b, double sigma_b_px,
                                       const std::vector<Eigen::Vector2d>& pixels) {
  mrcal_lensmodel_t model_b;
  if (pixels.empty() || !mrcal_lensmodel_from_name(&model_b, b.lensmodel.c_str()) ||
      model_b.type < 0)
    return -1;
  const int n = static_cast<int>(pixels.size());
  // Stacked gradients of both solves (independent), and the rotation's effect on b's
  // projection of the ray (dq/dr = -dq/dp [ray]x at r = 0).
  Eigen::MatrixXd Ga(2 * n, a.state_covariance_per_px2.rows());
  Eigen::MatrixXd Gb(2 * n, b.state_covariance_per_px2.rows());
  Eigen::MatrixXd A(2 * n, 3);
  for (int i = 0; i < n; ++i) {
    Eigen::MatrixXd G;
    if (!ProjectionGradient(a, pixels[i], 0, &G)) return -1;
    Ga.middleRows(2 * i, 2) = G;
    if (!ProjectionGradient(b, pixels[i], 0, &G)) return -1;
    Gb.middleRows(2 * i, 2) = G;
    const mrcal_point2_t q{{pixels[i].x(), pixels[i].y()}};
    mrcal_point3_t v, dq_dp[2];
    mrcal_point2_t q_back;
    if (!mrcal_unproject(&v, &q, 1, &model_b, b.intrinsics.data()) ||
        !mrcal_project(&q_back, dq_dp, nullptr, &v, 1, &model_b, b.intrinsics.data()))
      return -1;
    const Eigen::Vector3d ray(v.x, v.y, v.z);
    Eigen::Matrix3d cross;
    cross << 0, -ray.z(), ray.y(), ray.z(), 0, -ray.x(), -ray.y(), ray.x(), 0;
    Eigen::Matrix<double, 2, 3> dq_dray;
    for (int row = 0; row < 2; ++row)
      for (int k = 0; k < 3; ++k) dq_dray(row, k) = dq_dp[row].xyz[k];
    A.middleRows(2 * i, 2) = -dq_dray * cross;
  }
  const Eigen::MatrixXd covariance =
      sigma_a_px * sigma_a_px * (Ga * a.state_covariance_per_px2 * Ga.transpose()) +
      sigma_b_px * sigma_b_px * (Gb * b.state_covariance_per_px2 * Gb.transpose());
  // The difference after the best rotation is (I - A pinv(A)) d: its expected squared norm is
  // the trace of the covariance with the rotation's subspace projected out.
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(A);
  const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(2 * n, 3);
  const double removed = (Q.transpose() * covariance * Q).trace();
  const double expected = std::max(0.0, covariance.trace() - removed) / n;
  return std::isfinite(expected) ? std::sqrt(expected) : -1;
}

double MedianBoardRange_m(const SolveResult& fit, const BoardSpec& spec) {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (int id = 0; id < spec.NumCorners(); ++id) centre += CornerPosition(spec, id);
  centre /= std::max(1, spec.NumCorners());
  std::vector<double> ranges;
  for (const ViewFit& view : fit.views) {
    double c[3];
    mrcal_transform_point_rt(c, nullptr, nullptr, view.rt_cam_from_board.data(), centre.data());
    ranges.push_back(Eigen::Vector3d(c[0], c[1], c[2]).norm());
  }
  if (ranges.empty()) return 0;
  std::nth_element(ranges.begin(), ranges.begin() + ranges.size() / 2, ranges.end());
  return ranges[ranges.size() / 2];
}

UncertaintyMap ComputeUncertaintyMap(const SolveResult& fit, int width, int height, double range_m,
                                     double sigma_px, const std::vector<Eigen::Vector2d>& observed,
                                     int cols) {
  UncertaintyMap map;
  map.range_m = range_m;
  map.sigma_px = sigma_px;
  map.cols = std::max(2, cols);
  map.rows = std::max(2, static_cast<int>(std::lround(map.cols * height / double(width))));
  map.stdev_px.assign(map.cols * map.rows, -1);
  const double cell_w = width / double(map.cols), cell_h = height / double(map.rows);
  for (int j = 0; j < map.rows; ++j)
    for (int i = 0; i < map.cols; ++i) {
      const Eigen::Vector2d pixel((i + 0.5) * cell_w - 0.5, (j + 0.5) * cell_h - 0.5);
      const double s = ProjectionUncertainty_px(fit, pixel, range_m, sigma_px);
      map.stdev_px[j * map.cols + i] = s;
      map.max_px = std::max(map.max_px, s);
    }
  map.centre_px = ProjectionUncertainty_px(
      fit, Eigen::Vector2d((width - 1) / 2.0, (height - 1) / 2.0), range_m, sigma_px);
  map.corners_px[0] = map.At(0, 0);
  map.corners_px[1] = map.At(map.cols - 1, 0);
  map.corners_px[2] = map.At(0, map.rows - 1);
  map.corners_px[3] = map.At(map.cols - 1, map.rows - 1);
  std::vector<bool> seen(map.stdev_px.size(), false);
  for (const Eigen::Vector2d& q : observed) {
    const int i = std::clamp(static_cast<int>((q.x() + 0.5) / cell_w), 0, map.cols - 1);
    const int j = std::clamp(static_cast<int>((q.y() + 0.5) / cell_h), 0, map.rows - 1);
    seen[j * map.cols + i] = true;
  }
  std::vector<double> values;
  for (size_t c = 0; c < seen.size(); ++c)
    if (seen[c] && map.stdev_px[c] >= 0) values.push_back(map.stdev_px[c]);
  if (!values.empty()) {
    std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
    map.median_observed_px = values[values.size() / 2];
  }
  return map;
}

}  // namespace fresco::calib
