// Numerical stability at the extremes: the cases the other tests do not already
// cover. Each asserts a concrete outcome (a bound, or a clean refusal). The README table
// "Numerical stability at the extremes" lists every case and the test that covers it.
#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "pipeline/core/camera.h"
#include "pipeline/core/scene.h"
#include "pipeline/paint/base_buffer.h"
#include "pipeline/paint/frame_warp.h"
#include "pipeline/paint/grouping.h"
#include "pipeline/synth/camera_path.h"
#include "pipeline/synth/procedural_scenes.h"

namespace fresco {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A 1 m x 1 m plane at z = 0 (normal +z) as one base buffer.
BaseBufferSet PlaneBuffers(const Scene& scene, const BaseBufferOptions& options) {
  const Grouping g = ComputeGrouping(scene.mesh, ComputeAdjacency(scene.mesh), 20.0);
  return BuildBaseBuffers(scene.mesh, g, options);
}

// The one buffer of a single-plane scene.
BaseBuffer OnlyBuffer(const Scene& scene, double texel_size_m,
                      int max_buffer_texels = BaseBufferOptions().max_buffer_texels) {
  BaseBufferOptions options;
  options.texel_size_m = texel_size_m;
  options.max_buffer_texels = max_buffer_texels;
  const BaseBufferSet set = PlaneBuffers(scene, options);
  EXPECT_EQ(set.buffers.size(), 1u);
  return set.buffers.empty() ? BaseBuffer() : set.buffers[0];
}

// Warps a uniform frame into `buffer` from a camera 3 m from the plane's centre, looking at
// it from `elevation_deg` above the plane (90 = head-on, < 0 = from behind).
WarpedBuffer WarpFromElevation(const BaseBuffer& buffer, const Camera& camera,
                               const cv::Mat& frame, double elevation_deg,
                               const WarpOptions& options) {
  const double e = elevation_deg * kPi / 180.0;
  const Eigen::Vector3d eye(0.0, -3.0 * std::cos(e), 3.0 * std::sin(e));
  FrameView view;
  view.camera = &camera;
  view.cam_from_local = LookAt(eye, Eigen::Vector3d::Zero());
  view.centre_local = eye;
  view.frame_bgr = &frame;
  WarpedBuffer warped;
  WarpFrameToBuffer(buffer, view, options, &warped);
  return warped;
}

TEST(Extremes, GrazingViewsAreNotPaintedAndWouldScoreNearZeroQuality) {
  const Scene scene = MakeTexturedPlaneScene(1.0, 1.0);
  const BaseBuffer buffer = OnlyBuffer(scene, 0.01);
  ASSERT_GT(buffer.num_surface_texels, 9000);
  const Camera camera = Camera::FromParams(LensModel::kPinhole, 640, 480, {500, 500, 319.5, 239.5});
  const cv::Mat frame(480, 640, CV_8UC3, cv::Scalar(10, 200, 30));
  WarpOptions options;  // max_view_angle_deg = 80 by default

  // Head-on-ish (45 deg): the whole plane is painted with the frame's colour.
  WarpedBuffer w = WarpFromElevation(buffer, camera, frame, 45.0, options);
  EXPECT_EQ(w.grazing, 0);
  EXPECT_GE(cv::countNonZero(w.valid), buffer.num_surface_texels);

  // Grazing: 0.5 deg to the surface (89.5 deg from the normal), and 5 deg: nothing painted,
  // every texel of the plane counted as grazing.
  for (double elevation : {0.5, 5.0}) {
    w = WarpFromElevation(buffer, camera, frame, elevation, options);
    EXPECT_EQ(cv::countNonZero(w.valid), 0) << elevation;
    EXPECT_EQ(w.in_view, 0) << elevation;
    EXPECT_GE(w.grazing, buffer.num_surface_texels) << elevation;
  }
  // From behind the surface (back-facing): also nothing.
  w = WarpFromElevation(buffer, camera, frame, -30.0, options);
  EXPECT_EQ(cv::countNonZero(w.valid), 0);
  EXPECT_GE(w.grazing, buffer.num_surface_texels);

  // With the limit opened to 89.9 deg the 0.5 deg view is painted, with the right colour,
  // but its quality (pixels per texel, f s cos / z) is tiny: the plane's near edge (2.5 m
  // away, z ~ 2.5) is seen at most atan(3 sin 0.5 deg / (3 cos 0.5 deg - 0.5)) ~ 0.6 deg from
  // the surface, so quality < 1.05 * 500 * 0.01 * sin(0.6 deg) / 2.5 ~ 0.022 pixels per texel:
  // any frontal view (quality ~1) replaces it under the quality policy.
  options.occlusion.max_view_angle_deg = 89.9;
  w = WarpFromElevation(buffer, camera, frame, 0.5, options);
  const int painted = cv::countNonZero(w.valid);
  EXPECT_GT(painted, buffer.num_surface_texels / 2);
  double max_quality = 0;
  cv::minMaxLoc(w.quality, nullptr, &max_quality, nullptr, nullptr, w.valid);
  const double e = 0.5 * kPi / 180;
  const double near_edge_deg = std::atan2(3 * std::sin(e), 3 * std::cos(e) - 0.5);
  const double quality_bound = 1.05 * 500 * 0.01 * std::sin(near_edge_deg) / 2.5;
  EXPECT_LT(quality_bound, 0.023);
  EXPECT_GT(max_quality, 0.0);
  EXPECT_LT(max_quality, quality_bound);
  const int expected[3] = {10, 200, 30};
  for (int c = 0; c < 3; ++c) {
    cv::Mat channel;
    cv::extractChannel(w.bgr, channel, c);
    double lo = 0, hi = 0;
    cv::minMaxLoc(channel, &lo, &hi, nullptr, nullptr, w.valid);
    EXPECT_GE(lo, expected[c] - 1) << c;
    EXPECT_LE(hi, expected[c] + 1) << c;
  }
}

TEST(Extremes, TinyAndHugeTexelSizesGiveBoundedBuffersOnTheSurface) {
  const Scene scene = MakeTexturedPlaneScene(1.0, 1.0);
  for (double tiny : {1e-6, 1e-9}) {
    BaseBufferOptions options;
    options.texel_size_m = tiny;
    options.max_buffer_texels = 1 << 18;
    const BaseBufferSet set = PlaneBuffers(scene, options);
    ASSERT_EQ(set.buffers.size(), 1u) << tiny;
    const BaseBuffer& b = set.buffers[0];
    // Coarsened to fit the cap: 512 x 512 texels for 1 m, so at least 1/512 m each ...
    EXPECT_LE(static_cast<long long>(b.width) * b.height, options.max_buffer_texels) << tiny;
    EXPECT_GE(b.texel_size_m, 1.0 / 512) << tiny;
    // ... and not much coarser than needed: over 90 % of the cap holds surface texels.
    EXPECT_GE(b.num_surface_texels, 0.9 * options.max_buffer_texels) << tiny;
    float max_off_plane = 0;
    for (int k = 0; k < b.NumTexels(); ++k)
      max_off_plane = std::max(max_off_plane, std::abs(b.Point(k).z()));
    EXPECT_LT(max_off_plane, 1e-6) << tiny;
  }
}

TEST(Extremes, HugeTexelsAreCappedSoTheSurfaceStillHasTexels) {
  // Texels larger than the surface would leave no texel centre on it: never painted.
  const Scene scene = MakeTexturedPlaneScene(1.0, 1.0);
  for (double huge : {10.0, 1e6, 1e300}) {
    const BaseBuffer b = OnlyBuffer(scene, huge);
    EXPECT_LE(b.texel_size_m, 1.0 / kMinTexelsAcross) << huge;
    EXPECT_GE(b.num_surface_texels, kMinTexelsAcross * kMinTexelsAcross) << huge;
    for (int k = 0; k < b.NumTexels(); ++k) {
      EXPECT_LT(std::abs(b.Point(k).z()), 1e-6) << huge;
      EXPECT_LE(std::abs(b.Point(k).x()), 0.5 + 1e-6) << huge;  // on the plane, not beside it
      EXPECT_LE(std::abs(b.Point(k).y()), 0.5 + 1e-6) << huge;
    }
  }
}

TEST(Extremes, TexelCountsBeyondTheIntRangeAreCappedNotOverflowed) {
  // 1 km at 1e-12 m: 1e15 texels across, far beyond int, before the cap brings it down.
  const Scene scene = MakeTexturedPlaneScene(1000.0, 1000.0);
  const int cap = 1 << 18;
  const BaseBuffer b = OnlyBuffer(scene, 1e-12, cap);
  EXPECT_GT(b.width, 0);
  EXPECT_GT(b.height, 0);
  EXPECT_LE(static_cast<long long>(b.width) * b.height, cap);
  EXPECT_GE(b.texel_size_m, 1000.0 / 512);
  EXPECT_GE(b.num_surface_texels, 0.9 * cap);
}

TEST(Extremes, ASliverThinnerThanATexelStillGetsATexelOnIt) {
  // One triangle 1 m long and 0.1 mm wide, 1 cm texels: no texel centre falls inside it.
  Scene scene;
  scene.mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0.5, 1e-4, 0}};
  scene.mesh.triangles = {{0, 1, 2}};
  scene.mesh.uvs.resize(1);
  scene.mesh.material = {0};
  scene.mesh.has_uv = {false};
  const BaseBuffer b = OnlyBuffer(scene, 0.01);
  ASSERT_GE(b.num_surface_texels, 1);
  for (int k = 0; k < b.NumTexels(); ++k) {
    if (!b.on_surface[k]) continue;
    EXPECT_NEAR(b.Point(k).x(), 0.5, 1e-6);  // the centroid
    EXPECT_NEAR(b.Point(k).y(), 1e-4 / 3, 1e-6);
    EXPECT_NEAR(b.Point(k).z(), 0, 1e-9);
  }
}

}  // namespace
}  // namespace fresco
