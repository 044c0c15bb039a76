#include "calib/lens_projection.h"

#include <cmath>
#include <limits>

#include <Eigen/Dense>
#include <Eigen/Geometry>

extern "C" {
#include <mrcal/mrcal.h>
}

namespace fresco::calib {
namespace {

bool Model(const std::string& name, const std::vector<double>& intrinsics,
           mrcal_lensmodel_t* lensmodel) {
  return mrcal_lensmodel_from_name(lensmodel, name.c_str()) && lensmodel->type >= 0 &&
         mrcal_lensmodel_num_params(lensmodel) == static_cast<int>(intrinsics.size());
}

Eigen::Matrix3d Rotation(const Eigen::Vector3d& r) {
  const double angle = r.norm();
  if (angle < 1e-15) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, r / angle).toRotationMatrix();
}

}  // namespace

int LensModelParamCount(const std::string& lensmodel) {
  mrcal_lensmodel_t model;
  if (!mrcal_lensmodel_from_name(&model, lensmodel.c_str()) || model.type < 0) return -1;
  return mrcal_lensmodel_num_params(&model);
}

bool ProjectPoints(const std::string& lensmodel, const std::vector<double>& intrinsics,
                   const std::vector<Eigen::Vector3d>& points_in_cam,
                   std::vector<Eigen::Vector2d>* pixels) {
  mrcal_lensmodel_t model;
  if (!Model(lensmodel, intrinsics, &model)) return false;
  std::vector<mrcal_point3_t> p(points_in_cam.size());
  for (size_t i = 0; i < p.size(); ++i)
    for (int k = 0; k < 3; ++k) p[i].xyz[k] = points_in_cam[i][k];
  std::vector<mrcal_point2_t> q(p.size());
  if (!mrcal_project(q.data(), nullptr, nullptr, p.data(), static_cast<int>(p.size()), &model,
                     intrinsics.data()))
    return false;
  pixels->resize(q.size());
  for (size_t i = 0; i < q.size(); ++i) (*pixels)[i] = Eigen::Vector2d(q[i].x, q[i].y);
  return true;
}

bool UnprojectPixels(const std::string& lensmodel, const std::vector<double>& intrinsics,
                     const std::vector<Eigen::Vector2d>& pixels,
                     std::vector<Eigen::Vector3d>* rays) {
  mrcal_lensmodel_t model;
  if (!Model(lensmodel, intrinsics, &model)) return false;
  std::vector<mrcal_point2_t> q(pixels.size());
  for (size_t i = 0; i < q.size(); ++i) q[i] = mrcal_point2_t{{pixels[i].x(), pixels[i].y()}};
  std::vector<mrcal_point3_t> v(q.size());
  if (!mrcal_unproject(v.data(), q.data(), static_cast<int>(q.size()), &model, intrinsics.data()))
    return false;
  rays->resize(v.size());
  for (size_t i = 0; i < v.size(); ++i) (*rays)[i] = Eigen::Vector3d(v[i].x, v[i].y, v[i].z);
  return true;
}

bool ProjectionDifferences_px(const std::string& lensmodel_a, const std::vector<double>& a,
                              const std::string& lensmodel_b, const std::vector<double>& b,
                              const std::vector<Eigen::Vector2d>& all_pixels,
                              std::vector<int>* compared, std::vector<Eigen::Vector2d>* diffs) {
  compared->clear();
  diffs->clear();
  std::vector<Eigen::Vector3d> all_rays;
  if (all_pixels.empty() || !UnprojectPixels(lensmodel_a, a, all_pixels, &all_rays)) return false;
  // Pixels where either model has no valid (un)projection (a strongly distorted model can fold
  // over near the imager's edge) are left out; fewer than half left: no comparison.
  std::vector<Eigen::Vector2d> pixels, back;
  std::vector<Eigen::Vector3d> rays;
  if (!ProjectPoints(lensmodel_b, b, all_rays, &back)) return false;
  for (size_t i = 0; i < all_pixels.size(); ++i)
    if (all_rays[i].allFinite() && all_rays[i].z() > 0 && back[i].allFinite()) {
      compared->push_back(static_cast<int>(i));
      pixels.push_back(all_pixels[i]);
      rays.push_back(all_rays[i]);
    }
  if (2 * pixels.size() < all_pixels.size() || pixels.empty()) return false;
  // Residuals for rotation r: project_b(R(r) ray) - pixel.
  auto residuals = [&](const Eigen::Vector3d& r, Eigen::VectorXd* out) {
    const Eigen::Matrix3d R = Rotation(r);
    std::vector<Eigen::Vector3d> rotated(rays.size());
    for (size_t i = 0; i < rays.size(); ++i) rotated[i] = R * rays[i];
    std::vector<Eigen::Vector2d> q;
    if (!ProjectPoints(lensmodel_b, b, rotated, &q)) return false;
    out->resize(2 * q.size());
    for (size_t i = 0; i < q.size(); ++i) out->segment<2>(2 * i) = q[i] - pixels[i];
    return out->allFinite();
  };
  Eigen::Vector3d r = Eigen::Vector3d::Zero();
  Eigen::VectorXd e;
  if (!residuals(r, &e)) return false;
  for (int iteration = 0; iteration < 8; ++iteration) {  // Gauss-Newton on 3 parameters
    Eigen::MatrixXd J(e.size(), 3);
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d rk = r;
      rk[k] += 1e-7;
      Eigen::VectorXd ek;
      if (!residuals(rk, &ek)) return false;
      J.col(k) = (ek - e) / 1e-7;
    }
    const Eigen::Vector3d step = (J.transpose() * J).ldlt().solve(-J.transpose() * e);
    Eigen::VectorXd e_new;
    if (!step.allFinite() || !residuals(r + step, &e_new) || e_new.squaredNorm() > e.squaredNorm())
      break;
    r += step;
    e = e_new;
    if (step.norm() < 1e-12) break;
  }
  diffs->resize(pixels.size());
  for (size_t i = 0; i < pixels.size(); ++i) (*diffs)[i] = e.segment<2>(2 * i);
  return true;
}

double ProjectionDifference_px(const std::string& lensmodel_a, const std::vector<double>& a,
                               const std::string& lensmodel_b, const std::vector<double>& b,
                               const std::vector<Eigen::Vector2d>& pixels) {
  std::vector<int> compared;
  std::vector<Eigen::Vector2d> diffs;
  if (!ProjectionDifferences_px(lensmodel_a, a, lensmodel_b, b, pixels, &compared, &diffs))
    return std::numeric_limits<double>::quiet_NaN();
  double sum = 0;
  for (const Eigen::Vector2d& d : diffs) sum += d.squaredNorm();
  return std::sqrt(sum / diffs.size());
}

}  // namespace fresco::calib
