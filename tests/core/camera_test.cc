// Camera models: agreement with libmrcal and OpenCV, COLMAP forms, Jacobians, unprojection
// (round trips, non-convergence, fold-back), points near the camera plane, map-scale poses.
#include "pipeline/core/camera.h"

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "pipeline/core/rigid3.h"

extern "C" {
#include <mrcal/mrcal.h>
}

namespace fresco {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A realistic calibrated camera (the OPENCV8 fit in DEPENDENCIES.md, plus rational terms).
Camera MakeCamera(LensModel model) {
  const std::vector<double> all = {1100, 1105,  645,    478,   -0.25,  0.09,
                                   8e-4, -5e-4, -0.015, 0.012, -0.004, 0.0007};
  std::vector<double> params;
  switch (model) {
    case LensModel::kPinhole:
      params.assign(all.begin(), all.begin() + 4);
      break;
    case LensModel::kOpenCV4:
      params.assign(all.begin(), all.begin() + 8);
      break;
    case LensModel::kOpenCV5:
      params.assign(all.begin(), all.begin() + 9);
      break;
    default:
      params = all;
  }
  return Camera::FromParams(model, 1280, 960, params);
}

// Random camera-frame points whose normalized radius is below `max_r`, at 0.2 to 50 m.
std::vector<Eigen::Vector3d> RandomPoints(int n, double max_r, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> xy(-max_r, max_r), depth(0.2, 50.0);
  std::vector<Eigen::Vector3d> points;
  while (static_cast<int>(points.size()) < n) {
    const double x = xy(rng), y = xy(rng), z = depth(rng);
    if (x * x + y * y > max_r * max_r) continue;
    points.emplace_back(x * z, y * z, z);
  }
  return points;
}

mrcal_lensmodel_t MrcalLensModel(LensModel model) {
  mrcal_lensmodel_t lensmodel;
  EXPECT_TRUE(mrcal_lensmodel_from_name(&lensmodel, LensModelName(model).c_str()));
  return lensmodel;
}

TEST(CameraLensModel, NamesRoundTripAndCounts) {
  const std::vector<std::pair<LensModel, int>> expected = {
      {LensModel::kPinhole, 4},      {LensModel::kOpenCV4, 8},       {LensModel::kOpenCV5, 9},
      {LensModel::kOpenCV8, 12},     {LensModel::kSimplePinhole, 3}, {LensModel::kColmapPinhole, 4},
      {LensModel::kSimpleRadial, 4}, {LensModel::kRadial, 5},        {LensModel::kColmapOpenCV, 8},
      {LensModel::kFullOpenCV, 12}};
  for (const auto& [model, count] : expected) {
    LensModel parsed;
    ASSERT_TRUE(LensModelFromName(LensModelName(model), &parsed)) << LensModelName(model);
    EXPECT_EQ(parsed, model);
    EXPECT_EQ(LensModelNumParams(model), count) << LensModelName(model);
    EXPECT_EQ(static_cast<int>(LensModelParamNames(model).size()), count);
  }
  EXPECT_EQ(LensModelName(LensModel::kOpenCV8), "LENSMODEL_OPENCV8");
  EXPECT_EQ(LensModelName(LensModel::kFullOpenCV), "FULL_OPENCV");
  EXPECT_FALSE(IsColmapModel(LensModel::kOpenCV5));
  EXPECT_TRUE(IsColmapModel(LensModel::kSimpleRadial));
  LensModel unused;
  EXPECT_FALSE(LensModelFromName("LENSMODEL_SPLINED_STEREOGRAPHIC", &unused));
  EXPECT_FALSE(LensModelFromName("opencv", &unused));
  // Our parameter counts are mrcal's.
  for (LensModel model :
       {LensModel::kPinhole, LensModel::kOpenCV4, LensModel::kOpenCV5, LensModel::kOpenCV8}) {
    const mrcal_lensmodel_t lensmodel = MrcalLensModel(model);
    EXPECT_EQ(mrcal_lensmodel_num_params(&lensmodel), LensModelNumParams(model));
  }
}

TEST(Camera, FromParamsAndParamsRoundTrip) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> value(-0.1, 0.1);
  for (LensModel model :
       {LensModel::kPinhole, LensModel::kOpenCV4, LensModel::kOpenCV5, LensModel::kOpenCV8,
        LensModel::kSimplePinhole, LensModel::kColmapPinhole, LensModel::kSimpleRadial,
        LensModel::kRadial, LensModel::kColmapOpenCV, LensModel::kFullOpenCV}) {
    std::vector<double> params(LensModelNumParams(model));
    for (double& p : params) p = value(rng);
    params[0] = 800.5;  // focal lengths
    if (LensModelParamNames(model)[1] == "fy") params[1] = 799.25;
    const Camera camera = Camera::FromParams(model, 640, 480, params);
    EXPECT_EQ(camera.Params(), params) << LensModelName(model);
    EXPECT_TRUE(camera.Validate("test").ok()) << camera.Validate("test").message();
    EXPECT_EQ(camera.HasDistortion(), params.size() > 4 || model == LensModel::kSimpleRadial);
    params.push_back(0.0);
    EXPECT_THROW(Camera::FromParams(model, 640, 480, params), std::invalid_argument);
  }
  const Camera simple = Camera::FromParams(LensModel::kRadial, 10, 20, {500, 4.5, 9.5, 0.1, 0.2});
  EXPECT_EQ(simple.fx, 500);
  EXPECT_EQ(simple.fy, 500);
  EXPECT_EQ(simple.cx, 4.5);
  EXPECT_EQ(simple.k1, 0.1);
  EXPECT_EQ(simple.k2, 0.2);
}

TEST(Camera, ValidateNamesSourceAndField) {
  Camera camera = MakeCamera(LensModel::kOpenCV8);
  EXPECT_TRUE(camera.Validate("cam.cameramodel").ok());

  Camera bad = camera;
  bad.fx = -3;
  EXPECT_EQ(bad.Validate("cam.cameramodel").message(),
            "cam.cameramodel: intrinsics: fx must be > 0 (got -3)");
  bad = camera;
  bad.k1 = kNaN;
  EXPECT_EQ(bad.Validate("cam.cameramodel").message(),
            "cam.cameramodel: intrinsics: k1 must be finite (got nan)");
  bad = camera;
  bad.cy = kInf;
  EXPECT_EQ(bad.Validate("x").message(), "x: intrinsics: cy must be finite (got inf)");
  bad = camera;
  bad.width = 0;
  EXPECT_EQ(bad.Validate("x").message(), "x: imagersize: width must be > 0 (got 0)");
  bad = camera;
  bad.height = -2;
  EXPECT_EQ(bad.Validate("x").message(), "x: imagersize: height must be > 0 (got -2)");
  bad = camera;
  bad.fy = 0;
  EXPECT_EQ(bad.Validate("x").message(), "x: intrinsics: fy must be > 0 (got 0)");

  Camera opencv4 = MakeCamera(LensModel::kOpenCV4);
  opencv4.k3 = 0.1;
  EXPECT_EQ(opencv4.Validate("x").message(),
            "x: intrinsics: k3 must be 0 for LENSMODEL_OPENCV4 (got 0.1)");
  Camera simple = Camera::FromParams(LensModel::kSimpleRadial, 640, 480, {500, 320, 240, 0.1});
  EXPECT_TRUE(simple.Validate("x").ok());
  simple.fy = 501;
  EXPECT_FALSE(simple.Validate("x").ok());
  simple.fy = simple.fx = -1;
  EXPECT_EQ(simple.Validate("x").message(), "x: intrinsics: f must be > 0 (got -1)");
}

TEST(Camera, ProjectAgreesWithMrcal) {
  for (LensModel model :
       {LensModel::kPinhole, LensModel::kOpenCV4, LensModel::kOpenCV5, LensModel::kOpenCV8}) {
    const Camera camera = MakeCamera(model);
    const std::vector<Eigen::Vector3d> points = RandomPoints(5000, 0.8, 11);
    std::vector<mrcal_point3_t> p(points.size());
    for (size_t i = 0; i < points.size(); ++i)
      p[i] = mrcal_point3_t{{points[i].x(), points[i].y(), points[i].z()}};
    std::vector<mrcal_point2_t> q(points.size());
    const mrcal_lensmodel_t lensmodel = MrcalLensModel(model);
    const std::vector<double> intrinsics = camera.Params();
    ASSERT_TRUE(mrcal_project(q.data(), nullptr, nullptr, p.data(), static_cast<int>(p.size()),
                              &lensmodel, intrinsics.data()));
    double max_error_px = 0, max_jacobian_error = 0;
    for (size_t i = 0; i < points.size(); ++i) {
      Eigen::Vector2d pixel;
      ASSERT_TRUE(camera.Project(points[i], &pixel)) << points[i].transpose();
      max_error_px = std::max(max_error_px, (pixel - Eigen::Vector2d(q[i].x, q[i].y)).norm());
      Eigen::Vector2d pixel_j;
      Eigen::Matrix<double, 2, 3> jacobian;
      ASSERT_TRUE(camera.ProjectWithJacobian(points[i], &pixel_j, &jacobian));
      EXPECT_LT((pixel_j - pixel).norm(), 1e-9);
      // mrcal's gradient, one point per call: libmrcal 2.2 writes dq_dp of every point of a
      // batch into the first slot (seen here with N = 2).
      mrcal_point2_t q_one;
      mrcal_point3_t dq_dp[2];
      ASSERT_TRUE(mrcal_project(&q_one, dq_dp, nullptr, &p[i], 1, &lensmodel, intrinsics.data()));
      for (int r = 0; r < 2; ++r)
        for (int c = 0; c < 3; ++c)
          max_jacobian_error =
              std::max(max_jacobian_error, std::abs(jacobian(r, c) - dq_dp[r].xyz[c]) /
                                               (1.0 + std::abs(dq_dp[r].xyz[c])));
    }
    EXPECT_LT(max_error_px, 1e-9) << LensModelName(model);
    EXPECT_LT(max_jacobian_error, 1e-12) << LensModelName(model);
  }
}

TEST(Camera, ProjectAgreesWithOpenCV) {
  for (LensModel model :
       {LensModel::kPinhole, LensModel::kOpenCV4, LensModel::kOpenCV5, LensModel::kOpenCV8}) {
    const Camera camera = MakeCamera(model);
    const std::vector<Eigen::Vector3d> points = RandomPoints(5000, 0.8, 12);
    std::vector<cv::Point3d> object;
    for (const Eigen::Vector3d& p : points) object.emplace_back(p.x(), p.y(), p.z());
    const cv::Matx33d k(camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
    // OpenCV's order is k1 k2 p1 p2 [k3 [k4 k5 k6]], as mrcal's; 8 terms = CALIB_RATIONAL_MODEL.
    const std::vector<double> params = camera.Params();
    const std::vector<double> distortion(params.begin() + 4, params.end());
    std::vector<cv::Point2d> image;
    cv::projectPoints(object, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), k, distortion, image);
    double max_error_px = 0;
    for (size_t i = 0; i < points.size(); ++i) {
      Eigen::Vector2d pixel;
      ASSERT_TRUE(camera.Project(points[i], &pixel));
      max_error_px =
          std::max(max_error_px, (pixel - Eigen::Vector2d(image[i].x, image[i].y)).norm());
    }
    EXPECT_LT(max_error_px, 1e-9) << LensModelName(model);
  }
}

TEST(Camera, ColmapModelsProjectAsTheirOpenCVForm) {
  const double f = 812.5, cx = 330.25, cy = 241.75, k1 = -0.21, k2 = 0.07;
  const std::vector<std::pair<Camera, Camera>> pairs = {
      {Camera::FromParams(LensModel::kSimplePinhole, 640, 480, {f, cx, cy}),
       Camera::FromParams(LensModel::kPinhole, 640, 480, {f, f, cx, cy})},
      {Camera::FromParams(LensModel::kColmapPinhole, 640, 480, {f, f + 3, cx, cy}),
       Camera::FromParams(LensModel::kPinhole, 640, 480, {f, f + 3, cx, cy})},
      {Camera::FromParams(LensModel::kSimpleRadial, 640, 480, {f, cx, cy, k1}),
       Camera::FromParams(LensModel::kOpenCV4, 640, 480, {f, f, cx, cy, k1, 0, 0, 0})},
      {Camera::FromParams(LensModel::kRadial, 640, 480, {f, cx, cy, k1, k2}),
       Camera::FromParams(LensModel::kOpenCV4, 640, 480, {f, f, cx, cy, k1, k2, 0, 0})},
      {Camera::FromParams(LensModel::kColmapOpenCV, 640, 480, {f, f, cx, cy, k1, k2, 1e-3, -2e-3}),
       Camera::FromParams(LensModel::kOpenCV4, 640, 480, {f, f, cx, cy, k1, k2, 1e-3, -2e-3})},
      {Camera::FromParams(LensModel::kFullOpenCV, 640, 480,
                          MakeCamera(LensModel::kOpenCV8).Params()),
       MakeCamera(LensModel::kOpenCV8)},
  };
  for (const auto& [colmap, opencv] : pairs) {
    for (const Eigen::Vector3d& point : RandomPoints(500, 0.7, 13)) {
      Eigen::Vector2d a, b;
      ASSERT_TRUE(colmap.Project(point, &a));
      ASSERT_TRUE(opencv.Project(point, &b));
      EXPECT_LT((a - b).norm(), 1e-12) << LensModelName(colmap.model);
    }
  }
}

TEST(Camera, JacobianMatchesCentralDifferences) {
  for (LensModel model : {LensModel::kPinhole, LensModel::kOpenCV5, LensModel::kOpenCV8}) {
    const Camera camera = MakeCamera(model);
    double max_error = 0;
    for (const Eigen::Vector3d& point : RandomPoints(1000, 0.8, 14)) {
      Eigen::Vector2d pixel;
      Eigen::Matrix<double, 2, 3> jacobian, numeric;
      ASSERT_TRUE(camera.ProjectWithJacobian(point, &pixel, &jacobian));
      for (int c = 0; c < 3; ++c) {
        const double h = 1e-6 * point.z();
        Eigen::Vector3d plus = point, minus = point;
        plus[c] += h;
        minus[c] -= h;
        Eigen::Vector2d pixel_plus, pixel_minus;
        ASSERT_TRUE(camera.Project(plus, &pixel_plus));
        ASSERT_TRUE(camera.Project(minus, &pixel_minus));
        numeric.col(c) = (pixel_plus - pixel_minus) / (2 * h);
      }
      max_error = std::max(
          max_error, ((jacobian - numeric).cwiseAbs().array() / (1.0 + jacobian.cwiseAbs().array()))
                         .maxCoeff());
    }
    EXPECT_LT(max_error, 1e-6) << LensModelName(model);
  }
}

// Every `step`-th pixel of the image plus every border pixel, and the image's outer edge
// (half a pixel beyond the border pixel centres).
std::vector<Eigen::Vector2d> ImagePixels(const Camera& camera, int step) {
  std::vector<Eigen::Vector2d> pixels;
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const bool border = u == 0 || v == 0 || u == camera.width - 1 || v == camera.height - 1;
      if (border || (u % step == 0 && v % step == 0)) pixels.emplace_back(u, v);
    }
  }
  const double right = camera.width - 0.5, bottom = camera.height - 0.5;
  pixels.emplace_back(-0.5, -0.5);
  pixels.emplace_back(right, -0.5);
  pixels.emplace_back(-0.5, bottom);
  pixels.emplace_back(right, bottom);
  return pixels;
}

// Unprojects every pixel, expects success, and returns the worst round-trip error.
double MaxRoundTripErrorPx(const Camera& camera, const std::vector<Eigen::Vector2d>& pixels) {
  double max_error_px = 0;
  for (const Eigen::Vector2d& pixel : pixels) {
    Eigen::Vector2d normalized;
    EXPECT_TRUE(camera.Unproject(pixel, &normalized)) << pixel.transpose();
    Eigen::Vector2d back;
    EXPECT_TRUE(camera.Project(normalized.homogeneous(), &back)) << pixel.transpose();
    max_error_px = std::max(max_error_px, (back - pixel).norm());
  }
  return max_error_px;
}

TEST(Camera, UnprojectRoundTripMildDistortion) {
  for (LensModel model :
       {LensModel::kPinhole, LensModel::kOpenCV4, LensModel::kOpenCV5, LensModel::kOpenCV8}) {
    const Camera camera = MakeCamera(model);
    const std::vector<Eigen::Vector2d> pixels = ImagePixels(camera, 9);
    EXPECT_LT(MaxRoundTripErrorPx(camera, pixels), 1e-6) << LensModelName(model);
    // Same answer as mrcal's unprojection.
    const mrcal_lensmodel_t lensmodel = MrcalLensModel(model);
    const std::vector<double> intrinsics = camera.Params();
    for (size_t i = 0; i < pixels.size(); i += 97) {
      const mrcal_point2_t q{{pixels[i].x(), pixels[i].y()}};
      mrcal_point3_t v;
      ASSERT_TRUE(mrcal_unproject(&v, &q, 1, &lensmodel, intrinsics.data()));
      Eigen::Vector2d normalized;
      ASSERT_TRUE(camera.Unproject(pixels[i], &normalized));
      EXPECT_NEAR(normalized.x(), v.x / v.z, 1e-9);
      EXPECT_NEAR(normalized.y(), v.y / v.z, 1e-9);
    }
  }
}

// Strong barrel distortion, fisheye-like: r_d = r (1 - 0.45 r^2 + ...) folds back at
// r ~ 0.86, distorted radius ~ 0.574.
Camera StrongBarrel(double focal_px) {
  return Camera::FromParams(LensModel::kOpenCV5, 640, 480,
                            {focal_px, focal_px, 319.5, 239.5, -0.45, 0.0, 1e-3, -5e-4, 0.0});
}

TEST(Camera, UnprojectRoundTripStrongDistortion) {
  const Camera camera = StrongBarrel(800);  // image corner at distorted radius 0.5
  EXPECT_NEAR(camera.fold_r2, 1.0 / (3 * 0.45), 1e-12);
  EXPECT_LT(MaxRoundTripErrorPx(camera, ImagePixels(camera, 5)), 1e-6);
}

TEST(Camera, UnprojectReportsNonConvergenceBeyondTheFold) {
  // With f = 400 px the image corners lie beyond the largest distorted radius the lens
  // reaches (0.574 ~ 230 px from the centre): no point maps there.
  const Camera camera = StrongBarrel(400);
  const double max_distorted_r = std::sqrt(camera.fold_r2) * (1 - 0.45 * camera.fold_r2);
  int unreachable = 0, reachable = 0;
  for (const Eigen::Vector2d& pixel : ImagePixels(camera, 4)) {
    const double r_d =
        std::hypot((pixel.x() - camera.cx) / camera.fx, (pixel.y() - camera.cy) / camera.fy);
    Eigen::Vector2d normalized;
    const bool ok = camera.Unproject(pixel, &normalized);
    if (ok) {
      // Whatever converges is right: on the first branch and reprojecting exactly.
      Eigen::Vector2d back;
      ASSERT_TRUE(camera.Project(normalized.homogeneous(), &back));
      EXPECT_LT((back - pixel).norm(), 1e-6) << pixel.transpose();
      EXPECT_LE(normalized.squaredNorm(), camera.fold_r2);
      ++reachable;
    } else {
      ++unreachable;
    }
    // Tangential terms shift the boundary slightly: judge only clear cases.
    if (r_d > 1.02 * max_distorted_r) {
      EXPECT_FALSE(ok) << pixel.transpose();
    }
    if (r_d < 0.97 * max_distorted_r) {
      EXPECT_TRUE(ok) << pixel.transpose();
    }
  }
  EXPECT_GT(unreachable, 1000);
  EXPECT_GT(reachable, 1000);
  Eigen::Vector2d normalized;
  EXPECT_FALSE(camera.Unproject(Eigen::Vector2d(0, 0), &normalized));
}

TEST(Camera, FoldBackOfPolynomialAndRationalModels) {
  // r_d = r (1 - 0.5 r^2 + 0.05 r^4) rises to 0.565 at r^2 = 0.764, falls below 0 and
  // rises again for r > 2.69: a point at r = 3 lands at r_d = 1.65 (inside a wide image),
  // where nothing on the first branch maps.
  Camera camera = Camera::FromParams(LensModel::kOpenCV4, 2000, 2000,
                                     {500, 500, 999.5, 999.5, -0.5, 0.05, 0, 0});
  EXPECT_NEAR(camera.fold_r2, (1.5 - std::sqrt(1.25)) / 0.5, 1e-12);
  const Eigen::Vector3d far_point(3.0, 0.0, 1.0);
  Eigen::Vector2d pixel;
  EXPECT_FALSE(camera.Project(far_point, &pixel));
  Eigen::Matrix<double, 2, 3> jacobian;
  EXPECT_FALSE(camera.ProjectWithJacobian(far_point, &pixel, &jacobian));
  // libmrcal (no fold check) puts it inside the image.
  const mrcal_lensmodel_t lensmodel = MrcalLensModel(LensModel::kOpenCV4);
  const std::vector<double> intrinsics = camera.Params();
  const mrcal_point3_t p{{3.0, 0.0, 1.0}};
  mrcal_point2_t q;
  ASSERT_TRUE(mrcal_project(&q, nullptr, nullptr, &p, 1, &lensmodel, intrinsics.data()));
  EXPECT_NEAR(q.x, 999.5 + 500 * 3 * (1 - 0.5 * 9 + 0.05 * 81), 1e-9);
  EXPECT_LT(q.x, camera.width);
  // Its pixel has a solution only on the second branch: Unproject must refuse it.
  Eigen::Vector2d normalized;
  EXPECT_FALSE(camera.Unproject(Eigen::Vector2d(q.x, q.y), &normalized));
  // Without the fold check the same pixel converges onto the second branch.
  Camera unchecked = camera;
  unchecked.fold_r2 = kInf;
  Eigen::Vector2d wrong;
  if (unchecked.Unproject(Eigen::Vector2d(q.x, q.y), &wrong)) {
    EXPECT_GT(wrong.squaredNorm(), camera.fold_r2);
  }
  // A pixel inside the fold's reach has two preimages; we return the first-branch one.
  ASSERT_TRUE(camera.Unproject(Eigen::Vector2d(999.5 + 500 * 0.4, 999.5), &normalized));
  EXPECT_LT(normalized.squaredNorm(), camera.fold_r2);
  EXPECT_NEAR(normalized.x() * (1 - 0.5 * normalized.squaredNorm() +
                                0.05 * std::pow(normalized.squaredNorm(), 2)),
              0.4, 1e-11);

  // OpenCV's rational model: r_d = r / (1 + r^2) turns at r = 1 (r_d = 0.5), then falls
  // back towards 0, so every r_d < 0.5 has a second preimage at 1/r.
  Camera rational = Camera::FromParams(LensModel::kOpenCV8, 2000, 2000,
                                       {500, 500, 999.5, 999.5, 0, 0, 0, 0, 0, 1.0, 0, 0});
  EXPECT_NEAR(rational.fold_r2, 1.0, 1e-12);
  ASSERT_TRUE(rational.Unproject(Eigen::Vector2d(999.5 + 500 * 0.4, 999.5), &normalized));
  EXPECT_NEAR(normalized.x(), 0.5, 1e-10);  // not 2.0
  EXPECT_FALSE(rational.Unproject(Eigen::Vector2d(999.5 + 500 * 0.6, 999.5), &normalized));
  EXPECT_FALSE(rational.Project(Eigen::Vector3d(2.0, 0.0, 1.0), &pixel));
  EXPECT_TRUE(rational.Project(Eigen::Vector3d(0.5, 0.0, 1.0), &pixel));

  // Mild models never turn within any practical field of view.
  EXPECT_EQ(MakeCamera(LensModel::kPinhole).fold_r2, kInf);
  EXPECT_GT(MakeCamera(LensModel::kOpenCV8).fold_r2, 1.0);
  // Hand-built cameras start with no fold limit until UpdateFoldR2().
  Camera by_hand;
  by_hand.k1 = -0.45;
  EXPECT_EQ(by_hand.fold_r2, kInf);
  by_hand.UpdateFoldR2();
  EXPECT_NEAR(by_hand.fold_r2, 1.0 / 1.35, 1e-12);
}

TEST(Camera, PointsNearTheCameraPlane) {
  for (LensModel model : {LensModel::kPinhole, LensModel::kOpenCV8}) {
    const Camera camera = MakeCamera(model);
    Eigen::Vector2d near_pixel, unit_pixel;
    // Tiny but positive z: same direction as a point at z = 1.
    ASSERT_TRUE(camera.Project(Eigen::Vector3d(1e-10, -2e-10, 1e-9), &near_pixel));
    ASSERT_TRUE(camera.Project(Eigen::Vector3d(0.1, -0.2, 1.0), &unit_pixel));
    EXPECT_LT((near_pixel - unit_pixel).norm(), 1e-9);
    Eigen::Vector2d pixel;
    Eigen::Matrix<double, 2, 3> jacobian;
    for (const Eigen::Vector3d& bad :
         {Eigen::Vector3d(0.1, 0.2, 0.0), Eigen::Vector3d(0.0, 0.0, 0.0),
          Eigen::Vector3d(0.1, 0.2, -1e-12), Eigen::Vector3d(0.1, 0.2, -3.0),
          Eigen::Vector3d(0.0, 0.0, -1.0), Eigen::Vector3d(kNaN, 0.0, 1.0),
          Eigen::Vector3d(0.0, 0.0, kNaN), Eigen::Vector3d(kInf, 0.0, 1.0),
          Eigen::Vector3d(0.0, 0.0, kInf)}) {
      EXPECT_FALSE(camera.Project(bad, &pixel)) << bad.transpose();
      EXPECT_FALSE(camera.ProjectWithJacobian(bad, &pixel, &jacobian)) << bad.transpose();
    }
  }
  // A point almost in the camera plane, off-axis: a pinhole maps it far off the image (a
  // finite pixel); a folding lens must refuse it rather than fold it into the image.
  Eigen::Vector2d pixel;
  EXPECT_TRUE(MakeCamera(LensModel::kPinhole).Project(Eigen::Vector3d(1.0, 0.0, 1e-9), &pixel));
  EXPECT_GT(pixel.x(), 1e11);
  EXPECT_FALSE(StrongBarrel(400).Project(Eigen::Vector3d(1.0, 0.0, 1e-9), &pixel));
  Eigen::Vector2d normalized;
  EXPECT_FALSE(MakeCamera(LensModel::kOpenCV8).Unproject(Eigen::Vector2d(kNaN, 0), &normalized));
}

TEST(Camera, MapScaleCoordinatesProjectAsAtTheOrigin) {
  const Camera camera = MakeCamera(LensModel::kOpenCV8);
  const Rigid3d cam_from_world(Rigid3d::QuaternionFromAxisAngle(Eigen::Vector3d(0.3, -0.2, 0.1)),
                               Eigen::Vector3d(0.4, -0.3, 2.0));
  // The same scene and camera moved to map coordinates, ~1e6 m from the origin, composed
  // naively in double (R (p + offset) + (t - R offset)): rounding at 1e6 m is ~1e-10 m.
  const Eigen::Vector3d offset(612345.678, 1012345.891, 312.5);
  const Rigid3d cam_from_map(cam_from_world.rotation,
                             cam_from_world.translation - cam_from_world.rotation * offset);
  std::mt19937 rng(15);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double max_error_px = 0;
  int projected = 0;
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d point_in_world(u(rng), u(rng), u(rng));
    Eigen::Vector2d at_origin, at_map;
    const bool ok_origin = camera.Project(cam_from_world * point_in_world, &at_origin);
    const bool ok_map = camera.Project(cam_from_map * (point_in_world + offset), &at_map);
    ASSERT_EQ(ok_origin, ok_map);
    if (!ok_origin) continue;
    ++projected;
    max_error_px = std::max(max_error_px, (at_origin - at_map).norm());
  }
  EXPECT_GT(projected, 1000);
  EXPECT_LT(max_error_px, 1e-6);
}

}  // namespace
}  // namespace fresco
