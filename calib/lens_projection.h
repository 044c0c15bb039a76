// Projection and unprojection through any mrcal lens model (by its full mrcal name), for
// comparing solved models and drawing pictures. (0,0) = centre of the top-left pixel.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace fresco::calib {

// False when mrcal does not know the model or the intrinsics count is wrong.
bool ProjectPoints(const std::string& lensmodel, const std::vector<double>& intrinsics,
                   const std::vector<Eigen::Vector3d>& points_in_cam,
                   std::vector<Eigen::Vector2d>* pixels);
// Rays (not normalised) for pixels.
bool UnprojectPixels(const std::string& lensmodel, const std::vector<double>& intrinsics,
                     const std::vector<Eigen::Vector2d>& pixels,
                     std::vector<Eigen::Vector3d>* rays);
// mrcal's parameter count for the model, or -1 for an unknown name.
int LensModelParamCount(const std::string& lensmodel);

// RMS distance (px) between two models of one camera over `pixels`: each pixel unprojected by
// `a`, rotated by the best-fitting small rotation, projected by `b` (the rotation absorbs the
// arbitrary camera-frame orientation each solve picks, as mrcal's projection diff does).
// Pixels either model cannot (un)project are skipped; NaN when more than half are.
double ProjectionDifference_px(const std::string& lensmodel_a, const std::vector<double>& a,
                               const std::string& lensmodel_b, const std::vector<double>& b,
                               const std::vector<Eigen::Vector2d>& pixels);
// The same per pixel: `diffs` (projected by b minus the pixel, after the best rotation) for
// the pixels `compared` (indices into `pixels`). False where ProjectionDifference_px is NaN.
bool ProjectionDifferences_px(const std::string& lensmodel_a, const std::vector<double>& a,
                              const std::string& lensmodel_b, const std::vector<double>& b,
                              const std::vector<Eigen::Vector2d>& pixels,
                              std::vector<int>* compared, std::vector<Eigen::Vector2d>* diffs);

}  // namespace fresco::calib
