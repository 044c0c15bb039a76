#include "calib/mrcal_solve.h"

#include <cmath>
#include <cstring>

#include <Eigen/Dense>

extern "C" {
#include <mrcal/mrcal.h>
}

namespace fresco::calib {
namespace {

// Everything mrcal_optimize and mrcal_optimizer_callback take, for one camera at the
// reference and N board poses.
struct Problem {
  mrcal_lensmodel_t lensmodel{};
  std::vector<double> intrinsics;
  std::vector<mrcal_pose_t> frames;  // board -> camera
  mrcal_calobject_warp_t warp{};
  std::vector<mrcal_observation_board_t> observations;
  std::vector<mrcal_point3_t> pool;  // (N, H, W): x, y, weight (< 0: absent/outlier)
  BoardGrid grid;
  int imagersize[2] = {0, 0};
  mrcal_problem_selections_t selections{};
  mrcal_problem_constants_t constants{-1.0, -1.0};

  int Nframes() const { return static_cast<int>(frames.size()); }
  int NumStates() const {
    return mrcal_num_states(1, 0, Nframes(), 0, 0, Nframes(), selections, &lensmodel);
  }
  int NumMeasurements() const {
    return mrcal_num_measurements(Nframes(), 0, grid.width_n, grid.height_n, 1, 0, Nframes(), 0, 0,
                                  selections, &lensmodel);
  }
  int MeasurementIndex(int view, int grid_index) const {
    return mrcal_measurement_index_boards(view, Nframes(), 0, grid.width_n, grid.height_n) +
           2 * grid_index;
  }
};

bool LensModelFromName(const std::string& name, mrcal_lensmodel_t* lensmodel) {
  return mrcal_lensmodel_from_name(lensmodel, name.c_str()) && lensmodel->type >= 0;
}

mrcal_problem_selections_t Selections(bool core, bool distortions, bool warp, bool regularize,
                                      bool outliers) {
  mrcal_problem_selections_t s;
  std::memset(&s, 0, sizeof(s));
  s.do_optimize_intrinsics_core = core;
  s.do_optimize_intrinsics_distortions = distortions;
  s.do_optimize_extrinsics = false;
  s.do_optimize_frames = true;
  s.do_optimize_calobject_warp = warp;
  s.do_apply_regularization = regularize;
  s.do_apply_outlier_rejection = outliers;
  return s;
}

// Runs mrcal_optimize; fills `x` (all measurements) when given.
Status Optimize(Problem* p, std::vector<double>* x) {
  const int Nstate = p->NumStates();
  std::vector<double> b(Nstate);
  if (x) x->assign(p->NumMeasurements(), 0.0);
  const mrcal_stats_t stats = mrcal_optimize(
      b.data(), Nstate * static_cast<int>(sizeof(double)), x ? x->data() : nullptr,
      x ? static_cast<int>(x->size() * sizeof(double)) : 0, p->intrinsics.data(), nullptr,
      p->frames.data(), nullptr, &p->warp, 1, 0, p->Nframes(), 0, 0, p->observations.data(),
      nullptr, p->Nframes(), 0, p->pool.data(), &p->lensmodel, p->imagersize, p->selections,
      &p->constants, p->grid.spacing_m, p->grid.width_n, p->grid.height_n, false, false);
  if (stats.rms_reproj_error__pixels < 0 || !std::isfinite(stats.rms_reproj_error__pixels))
    return Status::Error("mrcal_optimize failed (bad arguments or a diverged solve)");
  return Status::Ok();
}

// All measurements at the problem's current state (no optimisation).
bool Evaluate(const Problem& p, const std::vector<double>& intrinsics,
              const std::vector<mrcal_pose_t>& frames, const mrcal_calobject_warp_t& warp,
              std::vector<double>* x) {
  std::vector<double> b(p.NumStates());
  x->assign(p.NumMeasurements(), 0.0);
  return mrcal_optimizer_callback(
      b.data(), static_cast<int>(b.size() * sizeof(double)), x->data(),
      static_cast<int>(x->size() * sizeof(double)), nullptr, intrinsics.data(), nullptr,
      frames.data(), nullptr, &warp, 1, 0, p.Nframes(), 0, 0, p.observations.data(), nullptr,
      p.Nframes(), 0, p.pool.data(), &p.lensmodel, p.imagersize, p.selections, &p.constants,
      p.grid.spacing_m, p.grid.width_n, p.grid.height_n, false);
}

// Covariance of the solved state per px^2 of corner noise, mrcal's form (its uncertainty
// docs): inv(J^T J) J_obs^T J_obs inv(J^T J), J over all `rows` (inlier board measurements,
// then the regularization terms), J_obs its first `observation_rows` rows (regularization is
// no noise). J by forward differences of mrcal_optimizer_callback. State: intrinsics, 6 per
// board pose (r, t), then the 2 warp terms when solved for.
Eigen::MatrixXd StateCovariance(const Problem& p, const std::vector<int>& rows,
                                int observation_rows) {
  struct Param {
    int kind, index;  // 0 intrinsics, 1 frame (index*6 + k), 2 warp
  };
  std::vector<Param> params;
  const int Nintr = static_cast<int>(p.intrinsics.size());
  for (int i = 0; i < Nintr; ++i) params.push_back({0, i});
  for (int i = 0; i < p.Nframes() * 6; ++i) params.push_back({1, i});
  if (p.selections.do_optimize_calobject_warp)
    for (int i = 0; i < 2; ++i) params.push_back({2, i});
  std::vector<double> x0;
  if (!Evaluate(p, p.intrinsics, p.frames, p.warp, &x0)) return {};
  Eigen::MatrixXd J(rows.size(), params.size());
  for (size_t c = 0; c < params.size(); ++c) {
    std::vector<double> intrinsics = p.intrinsics;
    std::vector<mrcal_pose_t> frames = p.frames;
    mrcal_calobject_warp_t warp = p.warp;
    double* value = params[c].kind == 0 ? &intrinsics[params[c].index]
                    : params[c].kind == 1
                        ? &reinterpret_cast<double*>(frames.data())[params[c].index]
                        : &warp.values[params[c].index];
    const double h = 1e-6 * std::max(1.0, std::abs(*value));
    *value += h;
    std::vector<double> x1;
    if (!Evaluate(p, intrinsics, frames, warp, &x1)) return {};
    for (size_t r = 0; r < rows.size(); ++r) J(r, c) = (x1[rows[r]] - x0[rows[r]]) / h;
  }
  const Eigen::MatrixXd JtJ = J.transpose() * J;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(JtJ);
  const Eigen::VectorXd& values = eigen.eigenvalues();
  const double floor = values.maxCoeff() * 1e-14;
  Eigen::VectorXd inverse = values;
  for (int i = 0; i < inverse.size(); ++i) inverse[i] = values[i] > floor ? 1.0 / values[i] : 0.0;
  const Eigen::MatrixXd JtJ_inverse =
      eigen.eigenvectors() * inverse.asDiagonal() * eigen.eigenvectors().transpose();
  if (observation_rows >= static_cast<int>(rows.size())) return JtJ_inverse;
  const Eigen::MatrixXd J_obs = J.topRows(observation_rows);
  return JtJ_inverse * (J_obs.transpose() * J_obs) * JtJ_inverse;
}

}  // namespace

Status SolveIntrinsics(const std::vector<BoardView>& views, const BoardSpec& spec, int width,
                       int height, const CalibrationSeed& seed, const SolveOptions& options,
                       SolveResult* result) {
  mrcal_lensmodel_t target;
  if (!LensModelFromName(options.lensmodel, &target))
    return Status::Error("lens model: mrcal does not know '" + options.lensmodel + "'");
  if (views.size() != seed.rt_cam_from_board.size())
    return Status::Error("internal error: one seed pose per view expected");
  const bool splined = target.type == MRCAL_LENSMODEL_SPLINED_STEREOGRAPHIC;

  Problem p;
  p.grid = MakeBoardGrid(spec);
  p.imagersize[0] = width;
  p.imagersize[1] = height;
  const int points_per_view = p.grid.width_n * p.grid.height_n;
  p.pool.assign(views.size() * points_per_view, mrcal_point3_t{{0.0, 0.0, -1.0}});
  int observed = 0;
  for (size_t v = 0; v < views.size(); ++v) {
    p.observations.push_back(mrcal_observation_board_t{{0, -1}, static_cast<int>(v)});
    mrcal_pose_t pose;
    for (int k = 0; k < 3; ++k) {
      pose.r.xyz[k] = seed.rt_cam_from_board[v][k];
      pose.t.xyz[k] = seed.rt_cam_from_board[v][3 + k];
    }
    p.frames.push_back(pose);
    for (const CornerObservation& c : views[v].corners) {
      mrcal_point3_t& q = p.pool[v * points_per_view + p.grid.grid_index_of_corner[c.id]];
      q.x = c.pixel.x();
      q.y = c.pixel.y();
      q.z = 1.0;
      ++observed;
    }
  }

  // Stage 1: core and board poses, distortion held (a stereographic core for splined).
  if (splined) {
    LensModelFromName("LENSMODEL_STEREOGRAPHIC", &p.lensmodel);
  } else {
    p.lensmodel = target;
  }
  p.intrinsics.assign(mrcal_lensmodel_num_params(&p.lensmodel), 0.0);
  p.intrinsics[0] = seed.fx;
  p.intrinsics[1] = seed.fy;
  p.intrinsics[2] = seed.cx;
  p.intrinsics[3] = seed.cy;
  if (p.intrinsics.size() >= 6) {  // OpenCV models: k1, k2 first
    p.intrinsics[4] = seed.k1;
    p.intrinsics[5] = seed.k2;
  }
  p.selections = Selections(true, false, false, false, false);
  FRESCO_RETURN_IF_ERROR(Optimize(&p, nullptr));

  // Stage 2: everything.
  if (splined) {
    std::vector<double> core(p.intrinsics.begin(), p.intrinsics.begin() + 4);
    p.lensmodel = target;
    p.intrinsics.assign(mrcal_lensmodel_num_params(&target), 0.0);
    std::copy(core.begin(), core.end(), p.intrinsics.begin());
  }
  const bool has_distortion = p.intrinsics.size() > 4;
  p.selections =
      Selections(true, has_distortion, options.optimize_board_warp, true, options.reject_outliers);
  std::vector<double> x;
  FRESCO_RETURN_IF_ERROR(Optimize(&p, &x));

  SolveResult out;
  char name[512];
  mrcal_lensmodel_name(name, sizeof(name), &p.lensmodel);
  out.lensmodel = name;
  out.intrinsics = p.intrinsics;
  out.board_warp_m = {p.warp.x2, p.warp.y2};
  out.num_states = p.NumStates();
  out.corners_observed = observed;
  double ssr = 0;
  std::vector<int> rows;
  for (size_t v = 0; v < views.size(); ++v) {
    ViewFit fit;
    for (int k = 0; k < 3; ++k) {
      fit.rt_cam_from_board[k] = p.frames[v].r.xyz[k];
      fit.rt_cam_from_board[3 + k] = p.frames[v].t.xyz[k];
    }
    double view_ssr = 0;
    int view_inliers = 0;
    for (const CornerObservation& c : views[v].corners) {
      const int g = p.grid.grid_index_of_corner[c.id];
      const int m = p.MeasurementIndex(static_cast<int>(v), g);
      const bool outlier = p.pool[v * points_per_view + g].z < 0;
      // x is weight * (projected - observed); weights are 1, outliers give 0: re-project.
      Eigen::Vector2d r(x[m], x[m + 1]);
      fit.outlier.push_back(outlier);
      if (outlier) {
        ++fit.outliers;
      } else {
        view_ssr += r.squaredNorm();
        ++view_inliers;
        rows.push_back(m);
        rows.push_back(m + 1);
      }
      fit.residual_px.push_back(r);
    }
    fit.rms_px = view_inliers ? std::sqrt(view_ssr / view_inliers) : 0;
    ssr += view_ssr;
    out.corners_used += view_inliers;
    out.outliers += fit.outliers;
    out.views.push_back(fit);
  }
  // Outliers have x = 0 from mrcal: fill their residuals by re-evaluating with them as inliers.
  if (out.outliers > 0) {
    Problem all = p;
    for (size_t v = 0; v < views.size(); ++v)
      for (const CornerObservation& c : views[v].corners)
        all.pool[v * points_per_view + p.grid.grid_index_of_corner[c.id]].z = 1.0;
    std::vector<double> x_all;
    if (Evaluate(all, all.intrinsics, all.frames, all.warp, &x_all))
      for (size_t v = 0; v < views.size(); ++v)
        for (size_t k = 0; k < views[v].corners.size(); ++k)
          if (out.views[v].outlier[k]) {
            const int m = p.MeasurementIndex(static_cast<int>(v),
                                             p.grid.grid_index_of_corner[views[v].corners[k].id]);
            out.views[v].residual_px[k] = Eigen::Vector2d(x_all[m], x_all[m + 1]);
          }
  }
  if (out.corners_used == 0) return Status::Error("mrcal rejected every corner as an outlier");
  out.rms_px = std::sqrt(ssr / out.corners_used);
  const int dof = 2 * out.corners_used - out.num_states;
  out.noise_sigma_px = dof > 0 ? std::sqrt(ssr / dof) : out.rms_px;
  if (options.compute_uncertainty) {
    const int observation_rows = static_cast<int>(rows.size());
    const int regularization =
        mrcal_measurement_index_regularization(p.Nframes(), 0, p.grid.width_n, p.grid.height_n);
    for (int m = regularization; m < p.NumMeasurements(); ++m) rows.push_back(m);
    out.state_covariance_per_px2 = StateCovariance(p, rows, observation_rows);
    const double sigma = out.noise_sigma_px * options.noise_inflation;
    for (int i = 0;
         i < static_cast<int>(out.intrinsics.size()) && i < out.state_covariance_per_px2.rows();
         ++i)
      out.intrinsics_stdev.push_back(sigma *
                                     std::sqrt(std::max(0.0, out.state_covariance_per_px2(i, i))));
  }
  for (double v : out.intrinsics)
    if (!std::isfinite(v)) return Status::Error("mrcal's solve diverged (non-finite intrinsics)");
  *result = std::move(out);
  return Status::Ok();
}

}  // namespace fresco::calib
