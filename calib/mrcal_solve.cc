#include "calib/mrcal_solve.h"

#include <malloc.h>

#include <climits>
#include <cmath>
#include <cstring>
#include <mutex>

#include <Eigen/Dense>
// CHOLMOD's compressed-column sparse matrix, which mrcal_optimizer_callback fills with the
// Jacobian (transposed: Nstate rows, Nmeasurements columns); mrcal.h only declares it.
#include <suitesparse/cholmod.h>

extern "C" {
#include <mrcal/mrcal.h>
// After mrcal.h: _mrcal_num_j_nonzero, the size of the Jacobian mrcal_optimizer_callback fills.
#include <mrcal/mrcal-internal.h>
}

#include "calib/abandonable.h"

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

// glibc serves allocations above its mmap threshold (at most 32 MiB) with fresh pages from
// mmap and unmaps them on free. CHOLMOD allocates and frees the transposed Jacobian (mrcal's
// board grid is 76 x 76 points for a 6x6 AprilGrid, absent points included: 20-80 MB) at every
// factorization of mrcal's solver, so every iteration faulted those pages in again, which cost
// more CPU than the factorization (`calib solve --model opencv4` on 10 AprilGrid images: 18.5 s
// CPU, 6.7 s of it in the kernel; 6.5 s with this). While any solve runs, large blocks stay on
// the heap and are reused; the last one to finish gives the memory back.
class ReuseLargeAllocations {
 public:
  ReuseLargeAllocations() {
    std::lock_guard<std::mutex> lock(Mutex());
    if (Users()++ == 0) {
      mallopt(M_MMAP_MAX, 0);
      mallopt(M_TRIM_THRESHOLD, INT_MAX);
    }
  }
  ~ReuseLargeAllocations() {
    std::lock_guard<std::mutex> lock(Mutex());
    if (--Users() == 0) {
      mallopt(M_MMAP_MAX, 65536);  // glibc's defaults
      mallopt(M_TRIM_THRESHOLD, 128 * 1024);
      malloc_trim(0);
    }
  }
  ReuseLargeAllocations(const ReuseLargeAllocations&) = delete;
  ReuseLargeAllocations& operator=(const ReuseLargeAllocations&) = delete;

 private:
  static std::mutex& Mutex() {
    static std::mutex mutex;
    return mutex;
  }
  static int& Users() {
    static int users = 0;
    return users;
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

// The state a fit solves for and returns, as bytes: a child process's fit sent back.
std::vector<std::pair<void*, size_t>> FitOutputs(Problem* p, std::vector<double>* x) {
  std::vector<std::pair<void*, size_t>> parts = {
      {p->intrinsics.data(), p->intrinsics.size() * sizeof(double)},
      {p->frames.data(), p->frames.size() * sizeof(mrcal_pose_t)},
      {&p->warp, sizeof(p->warp)},
      {p->pool.data(), p->pool.size() * sizeof(mrcal_point3_t)}};  // outliers marked
  if (x) parts.push_back({x->data(), x->size() * sizeof(double)});
  return parts;
}

// Optimize in a child process (SolveOptions::cancelled, abandonable.h): the fit's outputs
// come back as bytes.
Status OptimizeAbandonably(Problem* p, std::vector<double>* x,
                           const std::function<bool()>& cancelled) {
  if (x) x->assign(p->NumMeasurements(), 0.0);
  std::string bytes;
  FRESCO_RETURN_IF_ERROR(RunAbandonably(
      "mrcal_optimize",
      [&](std::string* out) {
        const Status fit = Optimize(p, x);
        if (!fit.ok()) return *out = fit.message(), false;
        for (const auto& [data, size] : FitOutputs(p, x))
          out->append(static_cast<const char*>(data), size);
        return true;
      },
      cancelled, &bytes));
  size_t at = 0;
  for (const auto& [data, size] : FitOutputs(p, x)) {
    if (at + size > bytes.size())
      return Status::Error("mrcal_optimize: the fit's process ended without its result");
    std::memcpy(data, bytes.data() + at, size);
    at += size;
  }
  return Status::Ok();
}

// A fit in this process, or one that can be abandoned when `options` ask.
Status Optimize(Problem* p, std::vector<double>* x, const SolveOptions& options) {
  if (options.cancelled && options.cancelled()) return Status::Error("cancelled");
  return options.cancelled ? OptimizeAbandonably(p, x, options.cancelled) : Optimize(p, x);
}

// All measurements at the problem's current state (no optimisation), and mrcal's Jacobian
// when `Jt` is given.
bool Evaluate(const Problem& p, std::vector<double>* x, cholmod_sparse* Jt = nullptr) {
  std::vector<double> b(p.NumStates());
  x->assign(p.NumMeasurements(), 0.0);
  return mrcal_optimizer_callback(
      b.data(), static_cast<int>(b.size() * sizeof(double)), x->data(),
      static_cast<int>(x->size() * sizeof(double)), Jt, p.intrinsics.data(), nullptr,
      p.frames.data(), nullptr, &p.warp, 1, 0, p.Nframes(), 0, 0, p.observations.data(), nullptr,
      p.Nframes(), 0, p.pool.data(), &p.lensmodel, p.imagersize, p.selections, &p.constants,
      p.grid.spacing_m, p.grid.width_n, p.grid.height_n, false);
}

// mrcal's analytic Jacobian at the problem's state, over the packed (unitless) state: column
// m of Jt holds d x[m] / d p for the states it depends on. `scale` (Nstate) converts: b = p *
// scale, so d x / d b = d x / d p / scale.
struct Jacobian {
  std::vector<int> column_start, state;
  std::vector<double> value, scale;
};

bool AnalyticJacobian(const Problem& p, Jacobian* jacobian) {
  const int Nstate = p.NumStates(), Nmeasurements = p.NumMeasurements();
  const int nonzero =
      _mrcal_num_j_nonzero(p.Nframes(), 0, p.grid.width_n, p.grid.height_n, 1, 0, p.Nframes(), 0, 0,
                           p.observations.data(), nullptr, p.selections, &p.lensmodel);
  jacobian->column_start.assign(Nmeasurements + 1, 0);
  jacobian->state.assign(nonzero, 0);
  jacobian->value.assign(nonzero, 0.0);
  cholmod_sparse Jt{};
  Jt.nrow = Nstate;
  Jt.ncol = Nmeasurements;
  Jt.nzmax = nonzero;
  Jt.p = jacobian->column_start.data();
  Jt.i = jacobian->state.data();
  Jt.x = jacobian->value.data();
  Jt.sorted = 1;
  Jt.packed = 1;
  Jt.itype = CHOLMOD_INT;
  Jt.xtype = CHOLMOD_REAL;
  Jt.dtype = CHOLMOD_DOUBLE;
  std::vector<double> x;
  if (!Evaluate(p, &x, &Jt)) return false;
  jacobian->scale.assign(Nstate, 1.0);
  mrcal_unpack_solver_state_vector(jacobian->scale.data(), 1, 0, p.Nframes(), 0, 0, p.selections,
                                   &p.lensmodel);
  return true;
}

// Covariance of the solved state per px^2 of corner noise, mrcal's form (its uncertainty
// docs): inv(J^T J) J_obs^T J_obs inv(J^T J), J over all `rows` (inlier board measurements,
// then the regularization terms), J_obs its first `observation_rows` rows (regularization is
// no noise). J is mrcal's own analytic Jacobian (mrcal_optimizer_callback), taken to the
// unpacked state: intrinsics, 6 per board pose (r, t), then the 2 warp terms when solved for.
Eigen::MatrixXd StateCovariance(const Problem& p, const std::vector<int>& rows,
                                int observation_rows) {
  Jacobian J;
  if (!AnalyticJacobian(p, &J)) return {};
  const int Nstate = static_cast<int>(J.scale.size());
  Eigen::MatrixXd JtJ_obs = Eigen::MatrixXd::Zero(Nstate, Nstate), JtJ = JtJ_obs;
  for (size_t r = 0; r < rows.size(); ++r) {
    Eigen::MatrixXd& sum = static_cast<int>(r) < observation_rows ? JtJ_obs : JtJ;
    const int begin = J.column_start[rows[r]], end = J.column_start[rows[r] + 1];
    for (int a = begin; a < end; ++a) {
      const double ja = J.value[a] / J.scale[J.state[a]];
      for (int c = begin; c < end; ++c)
        sum(J.state[a], J.state[c]) += ja * J.value[c] / J.scale[J.state[c]];
    }
  }
  JtJ += JtJ_obs;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(JtJ);
  const Eigen::VectorXd& values = eigen.eigenvalues();
  const double floor = values.maxCoeff() * 1e-14;
  Eigen::VectorXd inverse = values;
  for (int i = 0; i < inverse.size(); ++i) inverse[i] = values[i] > floor ? 1.0 / values[i] : 0.0;
  const Eigen::MatrixXd JtJ_inverse =
      eigen.eigenvectors() * inverse.asDiagonal() * eigen.eigenvectors().transpose();
  if (observation_rows >= static_cast<int>(rows.size())) return JtJ_inverse;
  return JtJ_inverse * JtJ_obs * JtJ_inverse;
}

// The board poses from the seed and every view's corners in the pool (the others absent);
// returns the corners observed.
int AddViews(const std::vector<BoardView>& views, const CalibrationSeed& seed, Problem* p) {
  const int points_per_view = p->grid.width_n * p->grid.height_n;
  p->pool.assign(views.size() * points_per_view, mrcal_point3_t{{0.0, 0.0, -1.0}});
  int observed = 0;
  for (size_t v = 0; v < views.size(); ++v) {
    p->observations.push_back(mrcal_observation_board_t{{0, -1}, static_cast<int>(v)});
    mrcal_pose_t pose;
    for (int k = 0; k < 3; ++k) {
      pose.r.xyz[k] = seed.rt_cam_from_board[v][k];
      pose.t.xyz[k] = seed.rt_cam_from_board[v][3 + k];
    }
    p->frames.push_back(pose);
    for (const CornerObservation& c : views[v].corners) {
      mrcal_point3_t& q = p->pool[v * points_per_view + p->grid.grid_index_of_corner[c.id]];
      q.x = c.pixel.x();
      q.y = c.pixel.y();
      q.z = 1.0;
      ++observed;
    }
  }
  return observed;
}

// Stage 1's model (a stereographic core for splined) and its intrinsics from the seed.
void SeedCore(const mrcal_lensmodel_t& target, bool splined, const CalibrationSeed& seed,
              Problem* p) {
  if (splined) {
    LensModelFromName("LENSMODEL_STEREOGRAPHIC", &p->lensmodel);
  } else {
    p->lensmodel = target;
  }
  p->intrinsics.assign(mrcal_lensmodel_num_params(&p->lensmodel), 0.0);
  p->intrinsics[0] = seed.fx;
  p->intrinsics[1] = seed.fy;
  p->intrinsics[2] = seed.cx;
  p->intrinsics[3] = seed.cy;
  if (p->intrinsics.size() >= 6) {  // OpenCV models: k1, k2 first
    p->intrinsics[4] = seed.k1;
    p->intrinsics[5] = seed.k2;
  }
}

// Each view's fit (board pose, residuals, outliers) into `out` from the measurements `x`;
// the inliers' measurement rows are appended to `rows`. Returns the inliers' sum of squares.
double AddViewFits(const std::vector<BoardView>& views, const Problem& p,
                   const std::vector<double>& x, SolveResult* out, std::vector<int>* rows) {
  const int points_per_view = p.grid.width_n * p.grid.height_n;
  double ssr = 0;
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
        rows->push_back(m);
        rows->push_back(m + 1);
      }
      fit.residual_px.push_back(r);
    }
    fit.rms_px = view_inliers ? std::sqrt(view_ssr / view_inliers) : 0;
    ssr += view_ssr;
    out->corners_used += view_inliers;
    out->outliers += fit.outliers;
    out->views.push_back(fit);
  }
  return ssr;
}

// Outliers have x = 0 from mrcal: fill their residuals by re-evaluating with them as inliers.
void FillOutlierResiduals(const std::vector<BoardView>& views, const Problem& p, SolveResult* out) {
  const int points_per_view = p.grid.width_n * p.grid.height_n;
  Problem all = p;
  for (size_t v = 0; v < views.size(); ++v)
    for (const CornerObservation& c : views[v].corners)
      all.pool[v * points_per_view + p.grid.grid_index_of_corner[c.id]].z = 1.0;
  std::vector<double> x_all;
  if (!Evaluate(all, &x_all)) return;
  for (size_t v = 0; v < views.size(); ++v)
    for (size_t k = 0; k < views[v].corners.size(); ++k)
      if (out->views[v].outlier[k]) {
        const int m = p.MeasurementIndex(static_cast<int>(v),
                                         p.grid.grid_index_of_corner[views[v].corners[k].id]);
        out->views[v].residual_px[k] = Eigen::Vector2d(x_all[m], x_all[m + 1]);
      }
}

// The state's covariance and the intrinsics' standard deviations; `rows`: the inliers'
// measurement rows (the regularization's are appended).
void AddUncertainty(const Problem& p, const SolveOptions& options, std::vector<int>* rows,
                    SolveResult* out) {
  const int observation_rows = static_cast<int>(rows->size());
  const int regularization =
      mrcal_measurement_index_regularization(p.Nframes(), 0, p.grid.width_n, p.grid.height_n);
  for (int m = regularization; m < p.NumMeasurements(); ++m) rows->push_back(m);
  out->state_covariance_per_px2 = StateCovariance(p, *rows, observation_rows);
  const double sigma = out->noise_sigma_px * options.noise_inflation;
  for (int i = 0;
       i < static_cast<int>(out->intrinsics.size()) && i < out->state_covariance_per_px2.rows();
       ++i)
    out->intrinsics_stdev.push_back(sigma *
                                    std::sqrt(std::max(0.0, out->state_covariance_per_px2(i, i))));
}

}  // namespace

Status SolveIntrinsics(const std::vector<BoardView>& views, const BoardSpec& spec, int width,
                       int height, const CalibrationSeed& seed, const SolveOptions& options,
                       SolveResult* result) {
  const ReuseLargeAllocations reuse;
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
  const int observed = AddViews(views, seed, &p);

  // Stage 1: core and board poses, distortion held (a stereographic core for splined).
  SeedCore(target, splined, seed, &p);
  p.selections = Selections(true, false, false, false, false);
  FRESCO_RETURN_IF_ERROR(Optimize(&p, nullptr, options));

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
  FRESCO_RETURN_IF_ERROR(Optimize(&p, &x, options));

  SolveResult out;
  char name[512];
  mrcal_lensmodel_name(name, sizeof(name), &p.lensmodel);
  out.lensmodel = name;
  out.intrinsics = p.intrinsics;
  out.board_warp_m = {p.warp.x2, p.warp.y2};
  out.board_warp_solved = options.optimize_board_warp;
  out.outlier_rejection = options.reject_outliers;
  out.num_states = p.NumStates();
  out.corners_observed = observed;
  std::vector<int> rows;
  const double ssr = AddViewFits(views, p, x, &out, &rows);
  if (out.outliers > 0) FillOutlierResiduals(views, p, &out);
  if (out.corners_used == 0) return Status::Error("mrcal rejected every corner as an outlier");
  out.rms_px = std::sqrt(ssr / out.corners_used);
  const int dof = 2 * out.corners_used - out.num_states;
  out.noise_sigma_px = dof > 0 ? std::sqrt(ssr / dof) : out.rms_px;
  if (options.compute_uncertainty) AddUncertainty(p, options, &rows, &out);
  for (double v : out.intrinsics)
    if (!std::isfinite(v)) return Status::Error("mrcal's solve diverged (non-finite intrinsics)");
  *result = std::move(out);
  return Status::Ok();
}

}  // namespace fresco::calib
