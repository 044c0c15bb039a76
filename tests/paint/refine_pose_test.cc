// Refinement through the pose (pipeline/paint/refine_pose.h) against known pose errors: the
// Jacobian against finite differences, the recovered correction against the one that made
// the matches, the chosen model against what the error contains, and each buffer's 2D
// correction against the warp it stands for.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "pipeline/paint/refine_pose.h"
#include "tests/paint/frontal_wall.h"

namespace fresco {
namespace {

constexpr double kDeg = M_PI / 180;

Camera Pinhole() { return Camera::FromParams(LensModel::kPinhole, 320, 240, {228, 228, 159.5, 119.5}); }
Camera Distorted() {
  return Camera::FromParams(LensModel::kOpenCV8, 320, 240,
                            {230, 226, 161, 118, -0.2, 0.05, 0.001, -0.002, 0.01, 0.02, 0.01, 0.003});
}

// A camera 2.5 m from the back wall of a room corner, looking at it: three planes.
Rigid3d Given() {
  return Rigid3d(Rigid3d::QuaternionFromAxisAngle(Eigen::Vector3d(0.1, -0.2, 0.05)),
                 Eigen::Vector3d(0.1, -0.05, 0.2));
}
std::vector<Eigen::Vector3d> CornerPoints(const Rigid3d& cam_from_local, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  const Rigid3d local_from_cam = cam_from_local.Inverse();
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 300; ++i) {
    // In camera coordinates: the back wall (z = 2.5), a side wall (x = 1.2), the floor (y = 0.9).
    Eigen::Vector3d p(u(rng), u(rng) * 0.75, 2.5);
    if (i % 3 == 1) p = Eigen::Vector3d(1.2, u(rng) * 0.75, 2.5 + u(rng) * 0.8);
    if (i % 3 == 2) p = Eigen::Vector3d(u(rng), 0.9, 2.5 + u(rng) * 0.8);
    points.push_back(local_from_cam * p);
  }
  return points;
}

// Matches as the stage makes them: what `truth_delta * given` projects each point to.
std::vector<PoseMatch> Matches(const Camera& camera, const Rigid3d& truth_delta,
                               double noise_px, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0, noise_px);
  std::vector<PoseMatch> matches;
  for (const Eigen::Vector3d& x : CornerPoints(Given(), seed)) {
    PoseMatch m;
    m.point_local = x;
    if (!camera.Project(truth_delta * Given() * x, &m.pixel)) continue;
    m.pixel += Eigen::Vector2d(noise(rng), noise(rng));
    matches.push_back(m);
  }
  return matches;
}

double RotationErrorDeg(const Rigid3d& a, const Rigid3d& b) {
  return RotationDifferenceDeg(a.rotation, b.rotation);
}

TEST(RefinePose, PixelJacobianMatchesFiniteDifferences) {
  for (const Camera& camera : {Pinhole(), Distorted()}) {
    const Eigen::Vector3d point(0.3, -0.2, 2.0);
    Eigen::Vector2d pixel;
    Eigen::Matrix<double, 2, 6> J;
    ASSERT_TRUE(PixelJacobian(camera, point, &pixel, &J));
    constexpr double h = 1e-6;
    for (int k = 0; k < 6; ++k) {
      Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
      d[k] = h;
      Eigen::Vector2d plus, minus;
      const Rigid3d up(Rigid3d::QuaternionFromAxisAngle(d.head<3>()), d.tail<3>());
      const Rigid3d down(Rigid3d::QuaternionFromAxisAngle(-d.head<3>()), -d.tail<3>());
      ASSERT_TRUE(camera.Project(up * point, &plus));
      ASSERT_TRUE(camera.Project(down * point, &minus));
      const Eigen::Vector2d numeric = (plus - minus) / (2 * h);
      EXPECT_NEAR((J.col(k) - numeric).norm(), 0, 1e-4 * (1 + numeric.norm())) << "column " << k;
    }
  }
}

TEST(RefinePose, RotationErrorIsRecoveredAndModelledAsRotation) {
  RefineOptions options;
  for (const Camera& camera : {Pinhole(), Distorted()}) {
    const Rigid3d truth(Rigid3d::QuaternionFromAxisAngle(Eigen::Vector3d(0.3, -0.4, 0.2) * kDeg),
                        Eigen::Vector3d::Zero());
    const PoseCorrection c = EstimatePoseCorrection(Matches(camera, truth, 0.1, 3), camera, Given(), options);
    ASSERT_TRUE(c.applied) << c.fallback;
    EXPECT_EQ(c.model, "rotation");
    EXPECT_LT(RotationErrorDeg(c.delta, truth), 0.01);  // 0.54 deg error, recovered to < 0.01
    EXPECT_GT(c.residual_before_px, 1.0);
    EXPECT_LT(c.residual_after_px, 0.2);
  }
}

TEST(RefinePose, TranslationIsModelledOnlyWhenTheMatchesNeedIt) {
  RefineOptions options;
  const Camera camera = Pinhole();
  const Rigid3d truth(Rigid3d::QuaternionFromAxisAngle(Eigen::Vector3d(0.2, 0.1, -0.1) * kDeg),
                      Eigen::Vector3d(0.03, -0.02, 0.05));
  const PoseCorrection c = EstimatePoseCorrection(Matches(camera, truth, 0.1, 4), camera, Given(), options);
  ASSERT_TRUE(c.applied) << c.fallback;
  EXPECT_EQ(c.model, "rotation+translation");
  EXPECT_LT(RotationErrorDeg(c.delta, truth), 0.05);
  EXPECT_LT((c.delta.translation - truth.translation).norm(), 0.005);  // of 6 cm
  // No error at all: no correction.
  const PoseCorrection none = EstimatePoseCorrection(Matches(camera, Rigid3d(), 0.1, 5), camera, Given(), options);
  EXPECT_FALSE(none.applied);
  EXPECT_EQ(none.model, "none");
}

TEST(RefinePose, OutliersDoNotDragTheFitAndTooFewMatchesFallBack) {
  RefineOptions options;
  const Camera camera = Pinhole();
  const Rigid3d truth(Rigid3d::QuaternionFromAxisAngle(Eigen::Vector3d(-0.5, 0.2, 0) * kDeg),
                      Eigen::Vector3d::Zero());
  std::vector<PoseMatch> matches = Matches(camera, truth, 0.1, 6);
  for (size_t i = 0; i < matches.size(); i += 5) matches[i].pixel += Eigen::Vector2d(7, -9);  // 20 %
  const PoseCorrection c = EstimatePoseCorrection(matches, camera, Given(), options);
  ASSERT_TRUE(c.applied) << c.fallback;
  EXPECT_LT(RotationErrorDeg(c.delta, truth), 0.02);
  EXPECT_LT(c.inliers, static_cast<int>(matches.size() * 0.85));
  matches.resize(5);
  const PoseCorrection few = EstimatePoseCorrection(matches, camera, Given(), options);
  EXPECT_FALSE(few.applied);
  EXPECT_EQ(few.fallback, "too few matches for a pose");
}

// A 2 m x 1.5 m wall buffer at z = 2.5 in front of the camera: the correction derived from
// a pose change is the warp it stands for: warped texel p (seen through the given pose)
// shows what the corrected pose puts at q = H p.
TEST(RefinePose, BufferCorrectionIsTheWarpThePoseChangeMakes) {
  const BaseBuffer buffer = FrontalWall(200, 150, 0.01, 2.5);
  for (const Camera& camera : {Pinhole(), Distorted()}) {
    const Rigid3d given(Rigid3d::QuaternionFromAxisAngle(Eigen::Vector3d(0.02, -0.03, 0.01)),
                        Eigen::Vector3d(0.05, 0, 0));
    const Rigid3d corrected =
        Rigid3d(Rigid3d::QuaternionFromAxisAngle(Eigen::Vector3d(0.4, -0.3, 0.2) * kDeg),
                Eigen::Vector3d::Zero()) * given;
    cv::Matx33d H;
    const cv::Rect within(20, 10, 160, 130);
    ASSERT_TRUE(BufferCorrectionFromPose(buffer, camera, given, corrected, within, &H));
    double worst = 0, moved = 0;
    for (int y = within.y; y < within.br().y; y += 13) {
      for (int x = within.x; x < within.br().x; x += 17) {
        const Eigen::Vector2d q(x, y);
        const cv::Vec3d ph = H.inv() * cv::Vec3d(x, y, 1);
        const Eigen::Vector2d p(ph[0] / ph[2], ph[1] / ph[2]);
        Eigen::Vector2d seen, wanted;
        ASSERT_TRUE(camera.Project(given * BufferPlanePoint(buffer, p), &seen));
        ASSERT_TRUE(camera.Project(corrected * BufferPlanePoint(buffer, q), &wanted));
        worst = std::max(worst, (seen - wanted).norm());
        moved = std::max(moved, (p - q).norm());
      }
    }
    EXPECT_GT(moved, 1.0);                                           // texels: a real correction
    EXPECT_LT(worst, camera.HasDistortion() ? 0.05 : 1e-3);  // pixels
  }
}

}  // namespace
}  // namespace fresco
