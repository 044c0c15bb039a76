// fresco gui [PROJECT.json] [--screenshot FILE.png] [--frames N] [--size WxH]
//            [--calib-images DIR --board BOARD [--model MODEL]]
//            [--poses verify|bootstrap [--poses-out DIR] [--poses-model DIR]]: the authoring
// app (ui/). With --screenshot it paints N frames (default 30), draws every panel, writes the
// window to FILE.png (and FILE.png.json: the panels and where they are) and exits 0; it
// needs a display (xvfb-run works). Built into the `fresco-gui` executable only, which
// `fresco gui` starts (gui_launcher.cc): the `fresco` CLI links no GL, GLFW or ImGui.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "app/commands.h"
#include "app/gui_command.h"
#include "calib/model_select.h"
#include "pipeline/core/project.h"
#include "ui/gl/app_window.h"

namespace fresco {

int RunGuiCommand(const CommandArgs& argv) {
  ArgSpec spec;
  spec.usage =
      "fresco gui [PROJECT.json] [--screenshot FILE.png] [--frames N] [--size WxH]\n"
      "           [--calib-images DIR --board BOARD [--model MODEL]]\n"
      "           [--poses verify|bootstrap [--poses-out DIR] [--poses-model DIR]]";
  spec.help =
      "The authoring app: 3D view, grouping editor, pipeline control, stage panels, timing and\n"
      "misalignment review (Dear ImGui + GLFW + OpenGL 3.3; needs a display).\n\n"
      "  --screenshot FILE  paint N frames, draw every panel, write the window to FILE (PNG)\n"
      "                     and FILE.json (the panels and their places), then exit\n"
      "  --frames N         frames to paint before the screenshot (default 30)\n"
      "  --size WxH         window size (default 1600x1000, times a dense monitor's scale)\n"
      "  --calib-images DIR open the Calibration panel on DIR and detect the board in its\n"
      "                     images (with --screenshot: detect and solve before the shot)\n"
      "  --board BOARD      the board for --calib-images (as `fresco calib solve --board`)\n"
      "  --model MODEL      lens model for --calib-images: auto (default), pinhole, opencv4,\n"
      "                     opencv5, opencv8, splined\n"
      "  --poses verify     open the Poses panel and run COLMAP on the project's frames, as\n"
      "                     `fresco poses verify` and `bootstrap` (with --screenshot: the run\n"
      "                     finishes before the shot)\n"
      "  --poses bootstrap  the same, then apply the bootstrapped poses to the project\n"
      "  --poses-out DIR    the run's output folder (default PROJECT_DIR/colmap-poses)\n"
      "  --poses-model DIR  use an earlier COLMAP text model (OUT/colmap/sparse_txt/0) instead\n"
      "                     of running COLMAP";
  spec.max_positional = 1;
  spec.options = {"--screenshot", "--frames", "--size",      "--calib-images", "--board",
                  "--model",      "--poses",  "--poses-out", "--poses-model"};
  Args args;
  if (int code = ParseVerbArgs("gui", argv, spec, &args); code >= 0) return code;
  GuiOptions options;
  if (!args.positional.empty()) options.project = args.positional[0];
  options.screenshot = args.Get("--screenshot");
  try {
    if (args.Has("--frames")) options.frames = std::stoi(args.Get("--frames"));
  } catch (const std::exception&) {
    return UsageError("gui", spec, "--frames: not a number: " + args.Get("--frames"));
  }
  if (options.frames < 1) return UsageError("gui", spec, "--frames must be >= 1");
  if (args.Has("--size") &&
      (std::sscanf(args.Get("--size").c_str(), "%dx%d", &options.width, &options.height) != 2 ||
       options.width < 320 || options.height < 240))
    return UsageError("gui", spec,
                      "--size: expected WxH of at least 320x240, got " + args.Get("--size"));
  options.size_given = args.Has("--size");
  options.calib_images = args.Get("--calib-images");
  options.calib_board = args.Get("--board");
  options.calib_model = args.Get("--model", "auto");
  if (options.calib_images.empty() && (args.Has("--board") || args.Has("--model")))
    return UsageError("gui", spec, "--board and --model go with --calib-images");
  if (!options.calib_images.empty()) {
    calib::BoardSpec board;
    if (!args.Has("--board")) return UsageError("gui", spec, "--calib-images needs --board");
    if (Status s = calib::ParseBoardSpec(options.calib_board, "--board", &board); !s.ok())
      return Fail(s);
    const auto& names = calib::LensModelShortNames();
    if (options.calib_model != "auto" &&
        std::find(names.begin(), names.end(), options.calib_model) == names.end())
      return UsageError("gui", spec,
                        "--model: '" + options.calib_model +
                            "' is not auto, pinhole, opencv4, opencv5, opencv8 or splined");
  }
  options.poses = args.Get("--poses");
  options.poses_out = args.Get("--poses-out");
  options.poses_model = args.Get("--poses-model");
  if (args.Has("--poses") && options.poses != "verify" && options.poses != "bootstrap")
    return UsageError(
        "gui", spec,
        std::string("--poses: expected verify or bootstrap, got '") + options.poses + "'");
  if (options.poses.empty() && (args.Has("--poses-out") || args.Has("--poses-model")))
    return UsageError("gui", spec, "--poses-out and --poses-model go with --poses");
  if (!options.poses.empty() && options.project.empty())
    return UsageError("gui", spec, "--poses needs a PROJECT.json");
  if (!options.poses_model.empty() && !std::filesystem::is_directory(options.poses_model))
    return Fail(Status::Error(options.poses_model + ": --poses-model: no such folder"));
  if (!options.screenshot.empty() && options.project.empty() && options.calib_images.empty())
    return UsageError("gui", spec, "--screenshot needs a PROJECT.json or --calib-images");
  if (!options.project.empty()) {  // bad input is exit 2 before any window opens
    Project project;
    if (Status s = LoadProject(options.project, {}, &project); !s.ok()) return Fail(s);
  }
  return RunGuiApp(options);
}

}  // namespace fresco
