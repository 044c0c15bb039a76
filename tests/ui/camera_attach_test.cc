// Attach to project driven headless through the Calibration panel (issue 58, item 5): a
// camera of another size than the project's frames, or an implausible lens, is refused
// before anything changes and the painting goes on; a fitting one asks first, and only
// "Attach and repaint" changes the project; Ctrl+Z restores the camera and says so.
#include <filesystem>
#include <map>

#include <gtest/gtest.h>
#include <imgui.h>
#include <imgui_internal.h>

#include "pipeline/core/cameramodel_io.h"
#include "pipeline/core/scaled_camera.h"
#include "tests/test_support.h"
#include "tests/ui/headless_ui.h"
#include "ui/core/camera_attach.h"
#include "ui/panels/panels.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using testing::Activate;
using testing::HeadlessApp;
using testing::TypeInto;

constexpr const char* kConfirm = "Attach camera?";

bool ConfirmationOpen() {
  ImGuiWindow* w = ImGui::FindWindowByName(kConfirm);
  return w != nullptr && w->Active;
}

// Writes `camera` as DIR/NAME.cameramodel and returns the path.
std::string WriteModel(const std::string& dir, const std::string& name, const Camera& camera) {
  CameraModelFile model;
  model.camera = camera;
  const std::string path = dir + "/" + name + ".cameramodel";
  const Status s = WriteCameraModel(path, model);
  EXPECT_TRUE(s.ok()) << s.message();
  return path;
}

TEST(CameraAttach, ACameraOfAnotherSizeIsRefusedAndAFittingOneAsksFirst) {
  const std::string dir = testing::MakeTempDir("attach");
  fs::copy(testing::Capture(), dir + "/capture", fs::copy_options::recursive);
  HeadlessApp app(dir + "/capture/project.json", 5);
  const std::string camera_before = app.state.project.camera;
  std::map<int, Camera> cameras;
  ASSERT_TRUE(ReadCameras(app.state.project.Resolve(camera_before), &cameras).ok());
  const Camera fits = cameras.begin()->second;
  ASSERT_EQ(fits.width, 160);
  const std::string right = WriteModel(dir, "right", fits);
  const std::string big = WriteModel(dir, "big", ScaledCamera(fits, 1024, 768));
  Camera off_centre = fits;
  off_centre.cx = 500;
  const std::string odd = WriteModel(dir, "odd", off_centre);

  app.Find(kCalibrationPanelTitle).open = true;
  app.Frames(3);
  const auto attach = [&](const std::string& path) {
    TypeInto(app, kCalibrationPanelTitle, "##attach", path);
    Activate(app, kCalibrationPanelTitle, "Attach to project...");
    app.Frames(2);
  };
  const auto painting_goes_on = [&](const char* after) {
    app.runner.WaitIdle();
    EXPECT_EQ(app.runner.Snapshot()->frame, 5) << after;
    EXPECT_EQ(app.runner.Snapshot()->status.rfind("error", 0), std::string::npos) << after;
    EXPECT_EQ(app.state.project.camera, camera_before) << after;
    EXPECT_FALSE(app.state.dirty) << after;
    EXPECT_FALSE(ConfirmationOpen()) << after;
  };

  // 1024x768 onto 160x120 frames: refused, naming both sizes and the frame.
  attach(big);
  EXPECT_EQ(app.state.message, "error: " + big +
                                   ": the camera is 1024x768 but the project's frames are "
                                   "160x120 ('000000.png'): not attached");
  EXPECT_EQ(app.ReportOf(kCalibrationPanelTitle, "attach_error"), app.state.message.substr(7));
  painting_goes_on("a camera of another size");

  // The right size, but the principal point far outside the image: not a real lens.
  attach(odd);
  EXPECT_NE(app.state.message.find("principal point"), std::string::npos) << app.state.message;
  painting_goes_on("an implausible lens");

  // A fitting camera: the confirmation first; Cancel keeps everything as it was.
  attach(right);
  EXPECT_TRUE(ConfirmationOpen());
  EXPECT_EQ(app.ReportOf(kCalibrationPanelTitle, "attach_error"), "");
  EXPECT_EQ(app.state.project.camera, camera_before) << "nothing changes before the answer";
  Activate(app, kConfirm, "Cancel");
  app.Frames(2);
  EXPECT_EQ(app.state.message, "camera not attached; the painting goes on as it was");
  painting_goes_on("Cancel");

  // Attach and repaint: the project's camera changes (relative to the project), undoably.
  Activate(app, kCalibrationPanelTitle, "Attach to project...");
  app.Frames(2);
  ASSERT_TRUE(ConfirmationOpen());
  Activate(app, kConfirm, "Attach and repaint");
  app.Frames(2);
  EXPECT_FALSE(ConfirmationOpen());
  EXPECT_EQ(app.state.project.camera, fs::absolute(right).lexically_normal().string())
      << "outside the project's folder: absolute";
  EXPECT_TRUE(app.state.dirty);
  EXPECT_EQ(app.state.message.rfind("camera: ", 0), 0u) << app.state.message;
  app.runner.WaitIdle();
  EXPECT_EQ(app.runner.Snapshot()->status.rfind("error", 0), std::string::npos)
      << app.runner.Snapshot()->status;

  // Ctrl+Z: the previous camera, and the status bar says so.
  app.CtrlTap('Z');
  EXPECT_EQ(app.state.project.camera, camera_before);
  EXPECT_EQ(app.state.message, "undone: camera back to " + camera_before);
  app.CtrlTap('Y');
  EXPECT_EQ(app.state.message, "redone: camera to " + app.state.project.camera);
  EXPECT_NE(app.state.project.camera, camera_before);
}

// The checks alone: sizes, and what makes a lens implausible.
TEST(CameraAttach, LensPlausibility) {
  Camera c;
  c.width = 640, c.height = 480, c.fx = c.fy = 500, c.cx = 319.5, c.cy = 239.5;
  EXPECT_TRUE(CheckLensPlausible(c, "c").ok());
  Camera squashed = c;
  squashed.fy = 150;
  EXPECT_NE(CheckLensPlausible(squashed, "c").message().find("fx / fy is 3.33"), std::string::npos);
  Camera narrow = c;
  narrow.fx = narrow.fy = 1e6;
  EXPECT_NE(CheckLensPlausible(narrow, "c").message().find("field of view"), std::string::npos);
  Camera folding = c;
  folding.model = LensModel::kOpenCV4;
  folding.k1 = -2;
  folding.UpdateFoldR2();
  EXPECT_NE(CheckLensPlausible(folding, "c").message().find("folds over"), std::string::npos)
      << CheckLensPlausible(folding, "c").message();
}

}  // namespace
}  // namespace fresco
