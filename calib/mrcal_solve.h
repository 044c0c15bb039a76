// The intrinsics solve, through libmrcal's C API (mrcal_optimize): one stationary camera
// (the reference frame) observing the board in several poses. Staged like
// mrcal-calibrate-cameras: first the intrinsics core and board poses with the distortion
// held at its seed (a stereographic core for the splined model), then everything, with the
// board's warp, mrcal's regularization and mrcal's outlier rejection.
// The 1-sigma uncertainty of every solved parameter comes from the covariance of the state
// at the optimum, sigma^2 inv(J^T J) J_obs^T J_obs inv(J^T J) as in mrcal's uncertainty
// propagation (J: mrcal's analytic Jacobian from mrcal_optimizer_callback, over intrinsics,
// board poses and warp; sigma from the inlier residuals with the degrees of freedom removed), times
// SolveOptions::noise_inflation for correlated corner noise. calib/uncertainty.h propagates
// the same covariance to projection uncertainty over the imager.
#pragma once

#include <array>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "calib/board.h"
#include "calib/observations.h"
#include "calib/seed.h"

namespace fresco::calib {

struct SolveOptions {
  std::string lensmodel = "LENSMODEL_OPENCV8";  // full mrcal name (splined with its config)
  bool reject_outliers = true;
  bool optimize_board_warp = true;
  bool compute_uncertainty = true;
  // Multiplies sigma in the covariance: > 1 when corner errors are positively correlated
  // (AprilTag corners of one tag share one quad fit); calib/noise_correlation.h.
  double noise_inflation = 1.0;
  // Optional: asked about every 0.1 s while a fit runs; true abandons the fit mid-way and the
  // solve fails with "cancelled". mrcal_optimize has no hook to stop it, so with this set each
  // fit runs in a child process (its result sent back whole, byte for byte what it would be
  // here), which is killed: nothing is left half-written.
  std::function<bool()> cancelled;
};

struct ViewFit {
  std::array<double, 6> rt_cam_from_board{};  // Rodrigues r, then t (m)
  std::vector<Eigen::Vector2d> residual_px;   // per corner of the view: projected - observed
  std::vector<bool> outlier;                  // per corner: rejected by mrcal
  double rms_px = 0;                          // over the view's inlier corners (2-D)
  int outliers = 0;
};

struct SolveResult {
  std::string lensmodel;
  std::vector<double> intrinsics;
  std::vector<double> intrinsics_stdev;  // 1-sigma per parameter (empty when not computed)
  // Covariance of the solved state per px^2 of corner noise (times sigma^2 gives Var):
  // (Nstate, Nstate) over the intrinsics, then 6 per view (rt_cam_from_board: r, t), then the
  // 2 warp terms when solved for. mrcal's form: inv(J^T J) J_obs^T J_obs inv(J^T J), so the
  // regularization terms are not counted as noise. Empty when not computed.
  Eigen::MatrixXd state_covariance_per_px2;
  std::vector<ViewFit> views;            // same order as the input views
  std::array<double, 2> board_warp_m{};  // mrcal's calobject_warp (x2, y2)
  bool board_warp_solved = false;        // SolveOptions::optimize_board_warp
  bool outlier_rejection = false;        // SolveOptions::reject_outliers
  double rms_px = 0;                     // sqrt(mean |residual|^2) over inlier corners
  double noise_sigma_px = 0;             // per coordinate: sqrt(SSR / (2 N_inliers - N_state))
  int corners_used = 0;                  // inlier corners
  int outliers = 0;                      // corners rejected by mrcal
  int num_states = 0;                    // parameters solved for
  int corners_observed = 0;
};

// `views` all need >= 4 corners and seed.rt_cam_from_board one pose per view.
Status SolveIntrinsics(const std::vector<BoardView>& views, const BoardSpec& spec, int width,
                       int height, const CalibrationSeed& seed, const SolveOptions& options,
                       SolveResult* result);

}  // namespace fresco::calib
