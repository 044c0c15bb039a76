// The 3D view's OpenGL renderer on a real context: in "groups" mode every group is drawn in
// its stable colour (ui/core/group_colour.h), the triangles of selected groups are tinted
// cyan and picked triangles striped white and black, and nothing else changes; a view-dependent
// layer shows where it has paint; after a pose verification COLMAP's path and the flagged frames'
// offsets are drawn over the model. Without a display the test runs itself again under xvfb-run
// (and skips when there is none).
#include <unistd.h>

#include <array>
#include <cstdlib>
#include <map>
#include <vector>

#include <GLFW/glfw3.h>
#include <gtest/gtest.h>

#include "pipeline/core/run_process.h"
#include "tests/test_support.h"
#include "tests/ui/headless_ui.h"
#include "ui/core/group_colour.h"
#include "ui/gl/gl.h"
#include "ui/gl/viewport_gl.h"

namespace fresco {
namespace {

using testing::Capture;

constexpr int kW = 160, kH = 120;

struct Rendered {
  std::vector<std::array<int, 4>> rgba;  // (kW * kH), GL rows (bottom up)
  std::vector<int> triangle;             // (kW * kH) triangle under each pixel, -1 for none
};

Rendered Render(GlViewport& viewport, const RunnerSnapshot& snap, const AppState& state,
                ViewportView* view) {
  const ImTextureID id = viewport.Render(snap, state, view, kW, kH);
  std::vector<unsigned char> pixels(4 * kW * kH);
  glBindTexture(GL_TEXTURE_2D, static_cast<GLuint>(reinterpret_cast<intptr_t>(id)));
  glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_UNSIGNED_BYTE, pixels.data());
  Rendered r;
  for (int i = 0; i < kW * kH; ++i)
    r.rgba.push_back({pixels[4 * i], pixels[4 * i + 1], pixels[4 * i + 2], pixels[4 * i + 3]});
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) r.triangle.push_back(viewport.Pick(x, y));
  return r;
}

// Re-runs this test program's GL tests under xvfb-run; false when that is not possible.
bool RanUnderXvfb() {
  const std::string xvfb = FindProgram("xvfb-run");
  if (xvfb.empty() || std::getenv("FRESCO_GL_CHILD")) return false;
  char self[4096] = {};
  if (readlink("/proc/self/exe", self, sizeof(self) - 1) <= 0) return false;
  setenv("FRESCO_GL_CHILD", "1", 1);
  const std::string log = testing::MakeTempDir("viewport-gl") + "/log.txt";
  int code = -1;
  EXPECT_TRUE(
      RunProcess({xvfb, "-a", "-s", "-screen 0 640x480x24", self, "--gtest_filter=ViewportGl.*"},
                 log, &code)
          .ok());
  EXPECT_EQ(code, 0) << testing::ReadText(log);
  return true;
}

TEST(ViewportGl, GroupsInStableColoursSelectionTinted) {
  const char* display = std::getenv("DISPLAY");
  if (!display || !*display) {
    if (!RanUnderXvfb()) GTEST_SKIP() << "no display and no xvfb-run";
    return;
  }
  ASSERT_TRUE(glfwInit());
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_VISIBLE, GLFW_FALSE);
  GLFWwindow* window = glfwCreateWindow(64, 64, "viewport test", nullptr, nullptr);
  ASSERT_NE(window, nullptr);
  glfwMakeContextCurrent(window);
  {
    AppState state;
    ASSERT_TRUE(state.Open(Capture() + "/project.json").ok());
    PipelineRunner runner;
    runner.Restart(state.project);
    runner.WaitIdle();
    const auto snap = runner.Snapshot();
    ASSERT_TRUE(snap->geometry);
    const SessionGeometry& geo = *snap->geometry;
    GlViewport viewport;
    ViewportView view;
    view.mode = ViewportView::Mode::kGroups;
    view.yaw_deg = 40;
    view.pitch_deg = 60;  // from above the room, outside it: several walls in view
    view.distance_m = 0;
    const Rendered plain = Render(viewport, *snap, state, &view);

    // Every drawn pixel has its group's colour times a shade (the same for r, g and b).
    std::map<int, int> pixels_of_group;
    for (int i = 0; i < kW * kH; ++i) {
      const int t = plain.triangle[i];
      if (t < 0) continue;
      const int g = geo.buffer_of_triangle[t];
      ASSERT_GE(g, 0);
      ++pixels_of_group[g];
      const auto rgb = GroupColour(StableGroupKey(geo.groups[g]));
      const double shade = plain.rgba[i][1] / (255.0 * rgb[1]);
      ASSERT_GT(shade, 0.4) << i;
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(plain.rgba[i][c], 255.0 * rgb[c] * shade, 3.0) << "pixel " << i << " c " << c;
    }
    ASSERT_GE(pixels_of_group.size(), 2u) << "several groups in view";
    int selected = -1;  // the group with the most pixels
    for (const auto& [g, n] : pixels_of_group)
      if (selected < 0 || n > pixels_of_group[selected]) selected = g;

    // Selecting that group tints exactly its pixels towards cyan.
    state.selected_groups = {selected};
    const Rendered tinted = Render(viewport, *snap, state, &view);
    int changed = 0, others_changed = 0;
    double cyan_gain = 0;
    for (int i = 0; i < kW * kH; ++i) {
      const int t = plain.triangle[i];
      const bool in_group = t >= 0 && geo.buffer_of_triangle[t] == selected;
      if (tinted.rgba[i] == plain.rgba[i]) continue;
      if (!in_group) {
        ++others_changed;
        continue;
      }
      ++changed;
      const auto& a = plain.rgba[i];
      const auto& b = tinted.rgba[i];
      cyan_gain += ((b[1] + b[2]) / 2.0 - b[0]) - ((a[1] + a[2]) / 2.0 - a[0]);
    }
    EXPECT_EQ(others_changed, 0);
    EXPECT_GT(changed, pixels_of_group[selected] * 9 / 10);
    EXPECT_GT(cyan_gain / std::max(1, changed), 15.0) << "towards cyan (0.2, 0.9, 1.0)";

    // Picking a triangle of it instead: white and black stripes over it, every such pixel
    // far from every group colour (the yellow it was drawn in sat between two of them).
    state.selected_groups.clear();
    state.selected_triangles = {geo.groups[selected].triangles.front()};
    const Rendered picked = Render(viewport, *snap, state, &view);
    int white = 0, black = 0;
    for (int i = 0; i < kW * kH; ++i) {
      if (picked.triangle[i] != geo.groups[selected].triangles.front()) {
        EXPECT_EQ(picked.rgba[i], plain.rgba[i]) << i;
        continue;
      }
      const std::array<float, 3> rgb = {picked.rgba[i][0] / 255.0f, picked.rgba[i][1] / 255.0f,
                                        picked.rgba[i][2] / 255.0f};
      EXPECT_GT(DistanceToNearestGroupColour(rgb), 0.7f) << "pixel " << i;
      white += picked.rgba[i][0] > 250 && picked.rgba[i][1] > 250 && picked.rgba[i][2] > 250;
      black += picked.rgba[i][0] < 5 && picked.rgba[i][1] < 5 && picked.rgba[i][2] < 5;
    }
    EXPECT_GT(white, 0);
    EXPECT_GT(black, 0);

    // Painted mode with a view-dependent layer: where the layer has paint the view shows it
    // (here solid green over grey buffers); with the layers switched off, the single texture.
    state.selected_triangles.clear();
    RunnerSnapshot layered = *snap;
    auto grey = std::make_shared<std::vector<cv::Mat>>();
    auto layers = std::make_shared<std::vector<RunnerSnapshot::LayerImages>>(1);
    (*layers)[0].centre_local = Eigen::Vector3f(0, 5, 0);
    for (const GroupSpec& g : geo.groups) {
      (void)g;
      grey->push_back(cv::Mat(8, 8, CV_8UC4, cv::Scalar(128, 128, 128, 255)));
      (*layers)[0].bgra.push_back(cv::Mat(8, 8, CV_8UC4, cv::Scalar(0, 255, 0, 255)));
    }
    layered.painted = grey;
    layered.layers = layers;
    layered.painted_version = snap->painted_version + 1;
    view.mode = ViewportView::Mode::kPainted;
    const Rendered with_layers = Render(viewport, layered, state, &view);
    view.view_layers = false;
    const Rendered single = Render(viewport, layered, state, &view);
    int green = 0, grey_pixels = 0, drawn = 0;
    for (int i = 0; i < kW * kH; ++i) {
      if (with_layers.triangle[i] < 0 || geo.buffer_of_triangle[with_layers.triangle[i]] < 0)
        continue;
      ++drawn;
      const auto& a = with_layers.rgba[i];
      green += a[1] > 200 && a[0] < 40 && a[2] < 40;
      const auto& b = single.rgba[i];
      grey_pixels += std::abs(b[0] - b[1]) < 3 && std::abs(b[1] - b[2]) < 3 && b[1] > 100;
    }
    ASSERT_GT(drawn, 100);
    EXPECT_EQ(green, drawn);
    EXPECT_EQ(grey_pixels, drawn);

    // After a pose verification: COLMAP's path in orange, a flagged frame's offset in red,
    // drawn over the model; none with the "COLMAP path" box off.
    view.view_layers = true;
    view.show_path = view.show_frustum = false;
    ASSERT_GE(geo.path.size(), 10u);
    for (size_t i = 0; i < geo.path.size(); ++i) {
      const Eigen::Vector3d given = geo.path[i].Centre();
      const bool flagged = i == geo.path.size() / 2;
      view.pose_check.push_back(
          {given, given + Eigen::Vector3d(0.05, 0, 0) * (flagged ? 20 : 1), flagged});
    }
    const auto count = [](const Rendered& r, bool red) {
      int n = 0;
      for (const auto& p : r.rgba)
        n += red ? p[0] > 200 && p[1] < 80 && p[2] < 80
                 : p[0] > 200 && p[1] > 100 && p[1] < 180 && p[2] < 60;
      return n;
    };
    const Rendered with_check = Render(viewport, layered, state, &view);
    EXPECT_GT(count(with_check, false), 20) << "COLMAP's path";
    EXPECT_GT(count(with_check, true), 3) << "the flagged frame's offset";
    view.show_pose_check = false;
    const Rendered without = Render(viewport, layered, state, &view);
    EXPECT_EQ(count(without, false), 0);
    EXPECT_EQ(count(without, true), 0);
  }
  glfwDestroyWindow(window);
  glfwTerminate();
}

}  // namespace
}  // namespace fresco
