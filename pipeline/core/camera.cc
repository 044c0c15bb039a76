#include "pipeline/core/camera.h"

#include <charconv>
#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>

namespace fresco {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

struct ModelInfo {
  LensModel model;
  const char* name;
  bool colmap;
  // Parameter names in the file's own order.
  std::vector<std::string> params;
};

const std::vector<ModelInfo>& ModelTable() {
  static const std::vector<ModelInfo> table = {
      {LensModel::kPinhole, "LENSMODEL_PINHOLE", false, {"fx", "fy", "cx", "cy"}},
      {LensModel::kOpenCV4,
       "LENSMODEL_OPENCV4",
       false,
       {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2"}},
      {LensModel::kOpenCV5,
       "LENSMODEL_OPENCV5",
       false,
       {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"}},
      {LensModel::kOpenCV8,
       "LENSMODEL_OPENCV8",
       false,
       {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6"}},
      {LensModel::kSimplePinhole, "SIMPLE_PINHOLE", true, {"f", "cx", "cy"}},
      {LensModel::kColmapPinhole, "PINHOLE", true, {"fx", "fy", "cx", "cy"}},
      {LensModel::kSimpleRadial, "SIMPLE_RADIAL", true, {"f", "cx", "cy", "k"}},
      {LensModel::kRadial, "RADIAL", true, {"f", "cx", "cy", "k1", "k2"}},
      {LensModel::kColmapOpenCV, "OPENCV", true, {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2"}},
      {LensModel::kFullOpenCV,
       "FULL_OPENCV",
       true,
       {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6"}},
  };
  return table;
}

const ModelInfo& Info(LensModel model) {
  for (const ModelInfo& info : ModelTable())
    if (info.model == model) return info;
  throw std::invalid_argument("unknown LensModel " + std::to_string(static_cast<int>(model)));
}

bool HasSingleFocal(LensModel model) {
  return model == LensModel::kSimplePinhole || model == LensModel::kSimpleRadial ||
         model == LensModel::kRadial;
}

// Shortest text that reads back as `value` ("-3", "0.1", "nan").
std::string FormatNumber(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

// The rational radial factor f(r2) = N(r2) / D(r2) and its derivative df/dr2.
struct Radial {
  double factor;
  double dfactor_dr2;
};

// Distorted normalized coordinates of (x, y) and, if `jacobian` is set, their 2x2 Jacobian
// d(x', y')/d(x, y) (symmetric: dx'/dy == dy'/dx).
inline Eigen::Vector2d DistortWithJacobian(const Camera& c, double x, double y,
                                           Eigen::Matrix2d* jacobian) {
  const double r2 = x * x + y * y;
  const double num = 1.0 + r2 * (c.k1 + r2 * (c.k2 + r2 * c.k3));
  const double den = 1.0 + r2 * (c.k4 + r2 * (c.k5 + r2 * c.k6));
  const double inv_den = 1.0 / den;
  const double f = num * inv_den;
  const double xy = x * y;
  const Eigen::Vector2d distorted(x * f + 2.0 * c.p1 * xy + c.p2 * (r2 + 2.0 * x * x),
                                  y * f + c.p1 * (r2 + 2.0 * y * y) + 2.0 * c.p2 * xy);
  if (jacobian) {
    const double dnum = c.k1 + r2 * (2.0 * c.k2 + r2 * 3.0 * c.k3);
    const double dden = c.k4 + r2 * (2.0 * c.k5 + r2 * 3.0 * c.k6);
    const double df = (dnum - f * dden) * inv_den;  // df/dr2
    const double off = 2.0 * xy * df + 2.0 * c.p1 * x + 2.0 * c.p2 * y;
    (*jacobian) << f + 2.0 * x * x * df + 2.0 * c.p1 * y + 6.0 * c.p2 * x, off, off,
        f + 2.0 * y * y * df + 6.0 * c.p1 * y + 2.0 * c.p2 * x;
  }
  return distorted;
}

}  // namespace

std::string LensModelName(LensModel model) { return Info(model).name; }

bool LensModelFromName(const std::string& name, LensModel* model) {
  for (const ModelInfo& info : ModelTable()) {
    if (name == info.name) {
      *model = info.model;
      return true;
    }
  }
  return false;
}

int LensModelNumParams(LensModel model) { return static_cast<int>(Info(model).params.size()); }

std::vector<std::string> LensModelParamNames(LensModel model) { return Info(model).params; }

bool IsColmapModel(LensModel model) { return Info(model).colmap; }

Camera Camera::FromParams(LensModel model, int width, int height,
                          const std::vector<double>& params) {
  const int expected = LensModelNumParams(model);
  if (static_cast<int>(params.size()) != expected) {
    throw std::invalid_argument("Camera::FromParams: " + LensModelName(model) + " takes " +
                                std::to_string(expected) + " parameters (got " +
                                std::to_string(params.size()) + ")");
  }
  Camera c;
  c.model = model;
  c.width = width;
  c.height = height;
  const double* p = params.data();
  if (HasSingleFocal(model)) {
    c.fx = c.fy = p[0];
    c.cx = p[1];
    c.cy = p[2];
    if (model == LensModel::kSimpleRadial) c.k1 = p[3];
    if (model == LensModel::kRadial) c.k1 = p[3], c.k2 = p[4];
  } else {
    c.fx = p[0], c.fy = p[1], c.cx = p[2], c.cy = p[3];
    if (expected >= 8) c.k1 = p[4], c.k2 = p[5], c.p1 = p[6], c.p2 = p[7];
    if (expected >= 9) c.k3 = p[8];
    if (expected >= 12) c.k4 = p[9], c.k5 = p[10], c.k6 = p[11];
  }
  c.UpdateFoldR2();
  return c;
}

std::vector<double> Camera::Params() const {
  switch (model) {
    case LensModel::kPinhole:
    case LensModel::kColmapPinhole:
      return {fx, fy, cx, cy};
    case LensModel::kOpenCV4:
    case LensModel::kColmapOpenCV:
      return {fx, fy, cx, cy, k1, k2, p1, p2};
    case LensModel::kOpenCV5:
      return {fx, fy, cx, cy, k1, k2, p1, p2, k3};
    case LensModel::kOpenCV8:
    case LensModel::kFullOpenCV:
      return {fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6};
    case LensModel::kSimplePinhole:
      return {fx, cx, cy};
    case LensModel::kSimpleRadial:
      return {fx, cx, cy, k1};
    case LensModel::kRadial:
      return {fx, cx, cy, k1, k2};
  }
  throw std::invalid_argument("unknown LensModel " + std::to_string(static_cast<int>(model)));
}

bool Camera::HasDistortion() const {
  return k1 != 0 || k2 != 0 || k3 != 0 || k4 != 0 || k5 != 0 || k6 != 0 || p1 != 0 || p2 != 0;
}

double Camera::ComputeFoldR2() const {
  // With s = r2, the distorted radius is r f(s), f = N/D, and d(r f)/dr has the sign of
  // Q(s) = N D + 2 s (N' D - N D') while D > 0. The valid range ends at the first s > 0
  // where Q or D reaches 0 (a turning point, or a pole of the rational model).
  auto valid = [this](double s) {
    const double n = 1.0 + s * (k1 + s * (k2 + s * k3));
    const double d = 1.0 + s * (k4 + s * (k5 + s * k6));
    const double dn = k1 + s * (2.0 * k2 + s * 3.0 * k3);
    const double dd = k4 + s * (2.0 * k5 + s * 3.0 * k6);
    const double q = n * d + 2.0 * s * (dn * d - n * dd);
    return d > 0.0 && q > 0.0;
  };
  if (k1 == 0 && k2 == 0 && k3 == 0 && k4 == 0 && k5 == 0 && k6 == 0)
    return std::numeric_limits<double>::infinity();
  // Scan s geometrically from 1e-8 (r = 1e-4) to 1e16 (r = 1e8, 0.6 microdegrees from the
  // camera plane): Q and D are polynomials of degree <= 6, so a 5% step only misses a
  // turning point that turns back within that step.
  double lo = 0.0, hi = -1.0;
  for (double s = 1e-8; s <= 1e16; s *= 1.05) {
    if (!valid(s)) {
      hi = s;
      break;
    }
    lo = s;
  }
  if (hi < 0.0) return std::numeric_limits<double>::infinity();
  for (int i = 0; i < 200 && hi - lo > 1e-15 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (valid(mid) ? lo : hi) = mid;
  }
  return lo;
}

Status Camera::Validate(const std::string& what) const {
  const std::string prefix = what + ": ";
  if (width <= 0)
    return Status::Error(prefix + "imagersize: width must be > 0 (got " + std::to_string(width) +
                         ")");
  if (height <= 0)
    return Status::Error(prefix + "imagersize: height must be > 0 (got " + std::to_string(height) +
                         ")");
  const bool single_focal = HasSingleFocal(model);
  const std::pair<const char*, double> fields[] = {{single_focal ? "f" : "fx", fx},
                                                   {"fy", fy},
                                                   {"cx", cx},
                                                   {"cy", cy},
                                                   {"k1", k1},
                                                   {"k2", k2},
                                                   {"p1", p1},
                                                   {"p2", p2},
                                                   {"k3", k3},
                                                   {"k4", k4},
                                                   {"k5", k5},
                                                   {"k6", k6}};
  for (const auto& [name, value] : fields) {
    if (!std::isfinite(value))
      return Status::Error(prefix + "intrinsics: " + name + " must be finite (got " +
                           FormatNumber(value) + ")");
  }
  if (!(fx > 0))
    return Status::Error(prefix + "intrinsics: " + (single_focal ? "f" : "fx") +
                         " must be > 0 (got " + FormatNumber(fx) + ")");
  if (single_focal && fy != fx)
    return Status::Error(prefix + "intrinsics: " + LensModelName(model) +
                         " has one focal length but fy (" + FormatNumber(fy) +
                         ") differs from f (" + FormatNumber(fx) + ")");
  if (!(fy > 0))
    return Status::Error(prefix + "intrinsics: fy must be > 0 (got " + FormatNumber(fy) + ")");
  // Parameters the model cannot hold must be 0, or writing the camera would drop them.
  const std::vector<std::string> names = LensModelParamNames(model);
  auto holds = [&](const std::string& name) {
    if (model == LensModel::kSimpleRadial && name == "k1") return true;  // COLMAP's "k"
    for (const std::string& n : names)
      if (n == name) return true;
    return false;
  };
  for (int i = 4; i < 12; ++i) {
    const auto& [name, value] = fields[i];
    if (value != 0 && !holds(name))
      return Status::Error(prefix + "intrinsics: " + name + " must be 0 for " +
                           LensModelName(model) + " (got " + FormatNumber(value) + ")");
  }
  return Status::Ok();
}

Eigen::Vector2d Camera::Distort(const Eigen::Vector2d& normalized) const {
  return DistortWithJacobian(*this, normalized.x(), normalized.y(), nullptr);
}

bool Camera::Project(const Eigen::Vector3d& point_in_cam, Eigen::Vector2d* pixel) const {
  // Straight-line code: the checks are combined at the end, so the common case does not
  // branch. The same formulas as DistortWithJacobian, without the Jacobian.
  const double z = point_in_cam.z();
  const double inv_z = 1.0 / z;
  const double x = point_in_cam.x() * inv_z;
  const double y = point_in_cam.y() * inv_z;
  const double r2 = x * x + y * y;
  const double num = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const double den = 1.0 + r2 * (k4 + r2 * (k5 + r2 * k6));
  const double f = num / den;
  const double two_xy = 2.0 * x * y;
  const double xd = x * f + p1 * two_xy + p2 * (r2 + 2.0 * x * x);
  const double yd = y * f + p1 * (r2 + 2.0 * y * y) + p2 * two_xy;
  const double u = fx * xd + cx;
  const double v = fy * yd + cy;
  pixel->x() = u;
  pixel->y() = v;
  // z < inf also catches a point at infinity (x = y = 0); r2 <= fold_r2 is false for NaN.
  return (z > 0.0) & (z < kInfinity) & (r2 <= fold_r2) & std::isfinite(u) & std::isfinite(v);
}

bool Camera::ProjectWithJacobian(const Eigen::Vector3d& point_in_cam, Eigen::Vector2d* pixel,
                                 Eigen::Matrix<double, 2, 3>* jacobian) const {
  const double z = point_in_cam.z();
  const double inv_z = 1.0 / z;
  const double x = point_in_cam.x() * inv_z;
  const double y = point_in_cam.y() * inv_z;
  Eigen::Matrix2d d_distorted_d_xy;
  const Eigen::Vector2d distorted = DistortWithJacobian(*this, x, y, &d_distorted_d_xy);
  *pixel = Eigen::Vector2d(fx * distorted.x() + cx, fy * distorted.y() + cy);
  // d(x, y)/d(X, Y, Z) = [1/z 0 -x/z; 0 1/z -y/z]
  Eigen::Matrix<double, 2, 3> d_xy_d_point;
  d_xy_d_point << inv_z, 0.0, -x * inv_z, 0.0, inv_z, -y * inv_z;
  *jacobian = Eigen::DiagonalMatrix<double, 2>(fx, fy) * d_distorted_d_xy * d_xy_d_point;
  const double r2 = x * x + y * y;
  return (z > 0.0) & (z < kInfinity) & (r2 <= fold_r2) & pixel->allFinite() & jacobian->allFinite();
}

Eigen::Vector2d Camera::PixelFromNormalized(const Eigen::Vector2d& normalized) const {
  const Eigen::Vector2d d = Distort(normalized);
  return Eigen::Vector2d(fx * d.x() + cx, fy * d.y() + cy);
}

bool Camera::Unproject(const Eigen::Vector2d& pixel, Eigen::Vector2d* normalized,
                       double tolerance_px) const {
  const Eigen::Vector2d target((pixel.x() - cx) / fx, (pixel.y() - cy) / fy);
  if (!target.allFinite()) return false;
  if (!HasDistortion()) {
    *normalized = target;
    return target.squaredNorm() <= fold_r2;
  }
  // Reprojection error in pixels of normalized point `x`.
  auto error_px = [&](const Eigen::Vector2d& x, Eigen::Vector2d* residual) {
    *residual = DistortWithJacobian(*this, x.x(), x.y(), nullptr) - target;
    return std::hypot(fx * residual->x(), fy * residual->y());
  };
  // Start from the undistorted guess, pulled inside the valid range if needed.
  Eigen::Vector2d x = target;
  const double r2_start = x.squaredNorm();
  if (r2_start > fold_r2) x *= std::sqrt(0.5 * fold_r2 / r2_start);
  Eigen::Vector2d residual;
  double error = error_px(x, &residual);
  // Newton converges quadratically: iterate well below the tolerance (to the limit of
  // double precision), then judge the result against it.
  const double goal_px = 1e-3 * tolerance_px;
  for (int iteration = 0; iteration < 50 && error > goal_px; ++iteration) {
    Eigen::Matrix2d jacobian;
    DistortWithJacobian(*this, x.x(), x.y(), &jacobian);
    const double det = jacobian.determinant();
    if (!(std::abs(det) > 1e-300)) break;
    const Eigen::Vector2d step = -(jacobian.inverse() * residual);
    if (!step.allFinite()) break;
    // Backtracking: accept the longest step (1, 1/2, 1/4, ...) that reduces the error and
    // stays within fold_r2, so the iteration never crosses onto a folded-back branch.
    bool improved = false;
    double t = 1.0;
    for (int halving = 0; halving < 40; ++halving, t *= 0.5) {
      const Eigen::Vector2d candidate = x + t * step;
      if (!(candidate.squaredNorm() <= fold_r2)) continue;
      Eigen::Vector2d candidate_residual;
      const double candidate_error = error_px(candidate, &candidate_residual);
      if (candidate_error < error) {
        x = candidate;
        residual = candidate_residual;
        error = candidate_error;
        improved = true;
        break;
      }
    }
    if (!improved) break;  // stalled: at the limit of precision, or at the fold
  }
  *normalized = x;
  return error <= tolerance_px && x.squaredNorm() <= fold_r2 && x.allFinite();
}

}  // namespace fresco
