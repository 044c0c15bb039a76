// The app's window: GLFW + OpenGL 3.3 core + Dear ImGui (GLFW and OpenGL3 backends), the
// main loop, and the --screenshot mode that paints N frames, draws every panel and writes
// the window to a PNG (plus FILE.json listing the panels and where they are).
#pragma once

#include <string>

namespace fresco {

struct GuiOptions {
  std::string project;     // "" = start without a project
  std::string screenshot;  // "" = interactive
  int frames = 30;         // --screenshot: frames to paint first
  int width = 1600, height = 1000;
  bool size_given = false;  // --size: the size as given (otherwise scaled on dense monitors)
  // Calibration panel: a folder to detect at start (--screenshot also solves before the shot).
  std::string calib_images, calib_board, calib_model = "auto";
  // Poses panel: "" (closed), "verify" (run COLMAP and verify at start; --screenshot waits
  // for it) or "bootstrap" (also apply the bootstrapped poses to the project); the output
  // folder ("" = PROJECT_DIR/colmap-poses) and an earlier COLMAP text model to use instead of
  // running COLMAP ("" = run it).
  std::string poses, poses_out, poses_model;
};

// Returns the process exit code (0 ok, 1 no display / GL failure, 2 bad project). A project
// that names a missing file is not bad input here: the app starts with the Project panel's
// path editor on it.
int RunGuiApp(const GuiOptions& options);

}  // namespace fresco
