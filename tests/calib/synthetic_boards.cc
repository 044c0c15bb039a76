#include "tests/calib/synthetic_boards.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "calib/lens_projection.h"

namespace fresco::calib::testing {

std::array<double, 6> SyntheticPose(int v, const BoardSpec& spec, const SyntheticCapture& capture) {
  const Eigen::Vector2d size = PatternSize_m(spec);
  const double a = 2 * M_PI * v / capture.views;
  const bool centre = capture.placement == Placement::kCentre;
  const double tilt = centre ? 0.05 : 0.6;
  const Eigen::Vector3d r(tilt * std::cos(a), tilt * std::sin(a), 0.1 * std::sin(3 * a));
  const double d = capture.distance_m, k = d / 0.42;
  Eigen::Vector3d centre_in_cam(0.09 * k * std::cos(a + 0.5), 0.072 * k * std::sin(a + 0.5),
                                d + 0.08 * k * std::cos(2 * a));
  if (centre) centre_in_cam.head<2>().setZero();
  if (capture.placement == Placement::kLeftSide)
    centre_in_cam.head<2>() =
        Eigen::Vector2d(-0.3 * d + 0.05 * d * std::cos(a + 0.5), 0.25 * d * std::sin(a + 0.5));
  const Eigen::Matrix3d R = Eigen::AngleAxisd(r.norm(), r.normalized()).toRotationMatrix();
  const Eigen::Vector3d board_centre(size.x() / 2, size.y() / 2, 0);
  const Eigen::Vector3d t = centre_in_cam - R * board_centre;
  return {r.x(), r.y(), r.z(), t.x(), t.y(), t.z()};
}

std::vector<BoardView> SyntheticViews(const BoardSpec& spec, const SyntheticCapture& capture) {
  std::mt19937 rng(capture.seed);
  std::normal_distribution<double> noise(0, capture.noise_px);
  std::vector<BoardView> views;
  for (int v = 0; v < capture.views; ++v) {
    const auto rt = SyntheticPose(v, spec, capture);
    const Eigen::Vector3d r(rt[0], rt[1], rt[2]);
    const Eigen::Matrix3d R = Eigen::AngleAxisd(r.norm(), r.normalized()).toRotationMatrix();
    std::vector<Eigen::Vector3d> points;
    for (int id = 0; id < spec.NumCorners(); ++id)
      points.push_back(R * CornerPosition(spec, id) + Eigen::Vector3d(rt[3], rt[4], rt[5]));
    std::vector<Eigen::Vector2d> q;
    EXPECT_TRUE(ProjectPoints(capture.lensmodel, capture.intrinsics, points, &q));
    BoardView view{"view" + std::to_string(v), {}};
    std::normal_distribution<double> shift(0, std::max(capture.tag_shift_px, 1e-300));
    Eigen::Vector2d tag_shift = Eigen::Vector2d::Zero();
    for (int id = 0; id < spec.NumCorners(); ++id) {
      if (capture.tag_shift_px > 0 && id % 4 == 0)
        tag_shift = Eigen::Vector2d(shift(rng), shift(rng));
      if (!(q[id].x() >= 0 && q[id].y() >= 0 && q[id].x() <= capture.width - 1 &&
            q[id].y() <= capture.height - 1))
        continue;
      view.corners.push_back({id, q[id] + tag_shift + Eigen::Vector2d(noise(rng), noise(rng))});
    }
    views.push_back(view);
  }
  return views;
}

CalibrationRun SolveSynthetic(const std::vector<BoardView>& views, const BoardSpec& spec, int width,
                              int height, const std::string& model, bool cross_validate) {
  CalibrateRequest request;
  request.board = spec;
  request.model = model;
  request.cross_validate = cross_validate;
  CalibrationRun run;
  run.width = width;
  run.height = height;
  run.views = views;
  const Status s = SolveViews(request, &run);
  EXPECT_TRUE(s.ok()) << s.message();
  return run;
}

BoardSpec Spec(const std::string& text) {
  BoardSpec spec;
  const Status s = ParseBoardSpec(text, "--board", &spec);
  EXPECT_TRUE(s.ok()) << s.message();
  return spec;
}

std::string AllWarnings(const CalibrationRun& run) {
  std::string all;
  for (const std::string& w : run.warnings) all += w + "\n";
  return all;
}

}  // namespace fresco::calib::testing
