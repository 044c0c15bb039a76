// Messages true to the state, the app driven headless (issue 58, item 6). Also there: a
// fold-over status line goes with its Undo (UiInput.GroupColoursStayAcrossEdits...) and
// undo says what it changed back (CameraAttach.*).
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "tests/test_support.h"
#include "tests/ui/headless_ui.h"

namespace fresco {
namespace {

using testing::HeadlessApp;

// A stage panel without a debug image says why, true to the worker's state (issue 58, item
// 6): never "they appear when paused" while paused with none shown.
TEST(StateMessages, AStagePanelSaysWhyItShowsNoDebugImage) {
  HeadlessApp app(testing::Capture() + "/project.json", 2);
  const std::string depth = "Stage: depth and visibility";
  ASSERT_TRUE(app.runner.Snapshot()->report_has_images) << "a sought frame is shown";
  EXPECT_NE(app.ReportOf(depth, "image"), "");
  EXPECT_EQ(app.ReportOf(depth, "note"), "");
  // Paused after playing: the last frame was painted between two publishes, without images.
  auto snap = std::make_shared<RunnerSnapshot>(*app.runner.Snapshot());
  for (StageReport& stage : snap->report.stages) stage.images.clear();
  snap->report_has_images = false;
  const auto note = [&] {
    app.ui.snapshot = snap;
    app.imgui.Frame(app.ui, app.panels, &app.input);
    return app.ReportOf(depth, "note");
  };
  EXPECT_EQ(note(), "(frame " + std::to_string(snap->report.frame) +
                        " was painted while playing, without debug images: Step or Apply (F5) "
                        "paints one with them)");
  snap->playing = true;
  EXPECT_EQ(note(), "(debug images appear when paused or stepping)");
  snap->playing = false;
  snap->report_has_images = true;
  EXPECT_EQ(note(), "(this stage drew no debug image for this frame)");
  // The real worker: played, then paused; whatever the last frame had, the note matches it.
  app.runner.Play();
  app.runner.Pause();
  app.runner.WaitIdle();
  app.Frames(2);
  const auto paused = app.runner.Snapshot();
  ASSERT_FALSE(paused->playing);
  EXPECT_EQ(app.ReportOf(depth, "note").find("appear when paused"), std::string::npos);
  if (paused->report_has_images) {
    EXPECT_NE(app.ReportOf(depth, "image"), "");
  }
}

}  // namespace
}  // namespace fresco
