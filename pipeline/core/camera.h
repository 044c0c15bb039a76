// Camera models: pinhole with OpenCV-style distortion, covering mrcal's LENSMODEL_PINHOLE,
// OPENCV4, OPENCV5, OPENCV8 and COLMAP's SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL,
// OPENCV, FULL_OPENCV. All are special cases of OpenCV's rational model
//   x' = x (1 + k1 r2 + k2 r4 + k3 r6) / (1 + k4 r2 + k5 r4 + k6 r6) + 2 p1 x y + p2 (r2 + 2x2)
//   y' = y (...) / (...) + p1 (r2 + 2y2) + 2 p2 x y
//   u = fx x' + cx,  v = fy y' + cy
// so one code path projects them all; `model` keeps the name for writing files back.
// Pixel convention: (0,0) is the centre of the top-left pixel (OpenCV, mrcal). COLMAP's
// (0.5,0.5) is converted when reading/writing COLMAP files, nowhere else.
#pragma once

#include <array>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pipeline/core/status.h"

namespace fresco {

enum class LensModel {
  kPinhole,        // mrcal LENSMODEL_PINHOLE: fx fy cx cy
  kOpenCV4,        // mrcal LENSMODEL_OPENCV4: fx fy cx cy k1 k2 p1 p2
  kOpenCV5,        // mrcal LENSMODEL_OPENCV5: fx fy cx cy k1 k2 p1 p2 k3
  kOpenCV8,        // mrcal LENSMODEL_OPENCV8: fx fy cx cy k1 k2 p1 p2 k3 k4 k5 k6
  kSimplePinhole,  // COLMAP SIMPLE_PINHOLE: f cx cy
  kColmapPinhole,  // COLMAP PINHOLE: fx fy cx cy
  kSimpleRadial,   // COLMAP SIMPLE_RADIAL: f cx cy k
  kRadial,         // COLMAP RADIAL: f cx cy k1 k2
  kColmapOpenCV,   // COLMAP OPENCV: fx fy cx cy k1 k2 p1 p2
  kFullOpenCV,     // COLMAP FULL_OPENCV: fx fy cx cy k1 k2 p1 p2 k3 k4 k5 k6
};

// Name as written in files: "LENSMODEL_OPENCV8", "SIMPLE_RADIAL", ...
std::string LensModelName(LensModel model);
// Parses either an mrcal or a COLMAP name. Returns false for unknown names.
bool LensModelFromName(const std::string& name, LensModel* model);
// Number of parameters in the file's own order for `model`.
int LensModelNumParams(LensModel model);
// Their names in that order: {"fx", "fy", "cx", "cy", "k1", ...}, {"f", "cx", "cy", "k"}, ...
std::vector<std::string> LensModelParamNames(LensModel model);
bool IsColmapModel(LensModel model);

struct Camera {
  LensModel model = LensModel::kPinhole;
  int width = 0;   // pixels
  int height = 0;  // pixels
  // Unified parameters, (0,0) = centre of the top-left pixel.
  double fx = 0, fy = 0, cx = 0, cy = 0;
  double k1 = 0, k2 = 0, k3 = 0, k4 = 0, k5 = 0, k6 = 0;  // radial (k4..k6: denominator)
  double p1 = 0, p2 = 0;                                  // tangential
  // Derived from k1..k6: the squared normalized radius r2 = x2 + y2 of the first turning
  // point of the radial mapping r -> r (1 + k1 r2 + ...) / (1 + k4 r2 + ...), where the lens
  // model starts folding back (strong barrel distortion, or OpenCV's rational model far
  // out); +inf when it never turns. Beyond it a point would land on a wrong pixel, so
  // Project and Unproject reject it. FromParams() sets it; after changing k1..k6 by hand,
  // call UpdateFoldR2() (left at +inf, nothing is rejected, as in OpenCV and mrcal).
  double fold_r2 = std::numeric_limits<double>::infinity();

  // Builds from parameters in the file's own order for `model` (mrcal order, or COLMAP
  // order with COLMAP's principal point already shifted to the (0,0) convention). Throws
  // std::invalid_argument when params.size() != LensModelNumParams(model) (readers check
  // the count first and report it as a Status). Sets fold_r2.
  static Camera FromParams(LensModel model, int width, int height,
                           const std::vector<double>& params);
  // Computes fold_r2 from k1..k6 (a scan plus bisection: microseconds, not for hot loops).
  double ComputeFoldR2() const;
  void UpdateFoldR2() { fold_r2 = ComputeFoldR2(); }
  // Parameters in the file's own order for `model` ((0,0) pixel convention).
  std::vector<double> Params() const;
  bool HasDistortion() const;
  // Checks sizes > 0, focal lengths > 0, everything finite, and that parameters `model`
  // cannot hold are 0 (and fy == fx for COLMAP's single-focal models), so Params() loses
  // nothing. `what` names the source: "cam.cameramodel: intrinsics: fx must be > 0 (got -3)".
  Status Validate(const std::string& what) const;

  // Distortion in normalized coordinates: (x, y) on the z=1 plane -> distorted (x', y').
  Eigen::Vector2d Distort(const Eigen::Vector2d& normalized) const;
  // Projects a camera-frame point. Returns false (pixel then unspecified) for z <= 0, a
  // point beyond fold_r2, or a non-finite result. Does not check the image bounds.
  bool Project(const Eigen::Vector3d& point_in_cam, Eigen::Vector2d* pixel) const;
  // Same, with the 2x3 Jacobian d(pixel)/d(point_in_cam) (analytic).
  bool ProjectWithJacobian(const Eigen::Vector3d& point_in_cam, Eigen::Vector2d* pixel,
                           Eigen::Matrix<double, 2, 3>* jacobian) const;
  // Pixel from normalized (z=1) coordinates.
  Eigen::Vector2d PixelFromNormalized(const Eigen::Vector2d& normalized) const;
  // Unprojects a pixel to normalized coordinates (x, y) with z = 1 (Newton on the
  // distortion, from the undistorted guess, with a backtracking line search that stays
  // within fold_r2). Returns false when it does not converge to `tolerance_px` in
  // reprojection, e.g. for pixels that no point within fold_r2 reaches.
  bool Unproject(const Eigen::Vector2d& pixel, Eigen::Vector2d* normalized,
                 double tolerance_px = 1e-6) const;
};

}  // namespace fresco
