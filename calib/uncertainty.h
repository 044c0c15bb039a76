// Projection uncertainty of a solved camera model: how far (1-sigma, pixels) the projection
// of a fixed point in space may move given the calibration's corner noise, over the imager.
//
// mrcal's method (its uncertainty docs; mrcal.projection_uncertainty in python3-mrcal 2.2),
// on our own solve's state covariance (SolveResult::state_covariance_per_px2): a pixel q is
// unprojected to the point p at range r (or the direction, at infinity); p is expressed in
// every board's frame; a perturbed solution maps those back through its own board poses and
// averages them (the camera frame is only defined relative to the boards), then projects with
// its own intrinsics. With G = dq/d(state) (intrinsics and board poses; the warp does not
// move q), Var(q) = sigma^2 G C G^T, and we report the worst-direction standard deviation
// sqrt(largest eigenvalue), as mrcal does.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "calib/mrcal_solve.h"

namespace fresco::calib {

// Worst-direction 1-sigma (px) of the projection of the point seen at `pixel` at `range_m`
// from the camera (<= 0: at infinity, rotations only), for corner noise `sigma_px`. Negative
// when it cannot be computed (no covariance, or the pixel does not unproject).
double ProjectionUncertainty_px(const SolveResult& fit, const Eigen::Vector2d& pixel,
                                double range_m, double sigma_px);

// dq/d(state) (2 x Nstate, the columns of SolveResult::state_covariance_per_px2) for the point
// seen at `pixel` at `range_m` (<= 0: at infinity). False when it cannot be computed.
bool ProjectionGradient(const SolveResult& fit, const Eigen::Vector2d& pixel, double range_m,
                        Eigen::MatrixXd* G);

// The RMS difference two independent solves `a` and `b` of a lens model that fits would show
// over `pixels` when compared as ProjectionDifference_px does (at infinity, after the best
// rotation): sqrt(trace(P (Cov_a + Cov_b) P) / N), P projecting out the rotation. -1 when
// it cannot be computed.
double ExpectedProjectionDifference_px(const SolveResult& a, double sigma_a_px,
                                       const SolveResult& b, double sigma_b_px,
                                       const std::vector<Eigen::Vector2d>& pixels);

struct UncertaintyMap {
  double range_m = 0;   // distance of the points (<= 0: at infinity)
  double sigma_px = 0;  // corner noise propagated (noise sigma times the correlation inflation)
  int cols = 0, rows = 0;
  std::vector<double> stdev_px;  // (rows, cols) at cell centres, row-major; < 0: not computed
  double centre_px = -1;         // at the imager's centre
  double corners_px[4] = {-1, -1, -1,
                          -1};     // corner cells: top-left, top-right, bottom-left, bottom-right
  double max_px = -1;              // over the whole map
  double median_observed_px = -1;  // median over cells holding an observed corner

  double At(int i, int j) const { return stdev_px[j * cols + i]; }
};

// Median distance from the camera to the boards' centres over the views (metres).
double MedianBoardRange_m(const SolveResult& fit, const BoardSpec& spec);

// The map over `cols` x rows cells (rows from the aspect ratio) at `range_m`. `observed`: the
// pixels of observed corners (for median_observed_px; may be empty).
UncertaintyMap ComputeUncertaintyMap(const SolveResult& fit, int width, int height, double range_m,
                                     double sigma_px, const std::vector<Eigen::Vector2d>& observed,
                                     int cols = 32);

}  // namespace fresco::calib
