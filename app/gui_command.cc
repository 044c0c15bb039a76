// fresco gui [PROJECT.json] [--screenshot FILE.png] [--frames N] [--size WxH]: the authoring
// app (ui/). With --screenshot it paints N frames (default 30), draws every panel, writes the
// window to FILE.png (and FILE.png.json: the panels and where they are) and exits 0; it
// needs a display (xvfb-run works).
#include <cstdio>
#include <iostream>

#include "app/commands.h"
#include "pipeline/core/project.h"
#ifdef FRESCO_HAVE_GUI
#include "ui/gl/app_window.h"
#endif

namespace fresco {

int RunVerbGui(const CommandArgs& argv) {
  ArgSpec spec;
  spec.usage = "fresco gui [PROJECT.json] [--screenshot FILE.png] [--frames N] [--size WxH]";
  spec.help =
      "The authoring app: 3D view, grouping editor, pipeline control, stage panels, timing and\n"
      "misalignment review (Dear ImGui + GLFW + OpenGL 3.3; needs a display).\n\n"
      "  --screenshot FILE  paint N frames, draw every panel, write the window to FILE (PNG)\n"
      "                     and FILE.json (the panels and their places), then exit\n"
      "  --frames N         frames to paint before the screenshot (default 30)\n"
      "  --size WxH         window size (default 1600x1000)";
  spec.max_positional = 1;
  spec.options = {"--screenshot", "--frames", "--size"};
  Args args;
  if (int code = ParseVerbArgs("gui", argv, spec, &args); code >= 0) return code;
#ifdef FRESCO_HAVE_GUI
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
  if (!options.screenshot.empty() && options.project.empty())
    return UsageError("gui", spec, "--screenshot needs a PROJECT.json");
  if (!options.project.empty()) {  // bad input is exit 2 before any window opens
    Project project;
    if (Status s = LoadProject(options.project, {}, &project); !s.ok()) return InputError(s);
  }
  return RunGuiApp(options);
#else
  std::cerr << "fresco gui: this build has no GUI (configured with -DFRESCO_GUI=OFF)\n";
  return kExitFailure;
#endif
}

}  // namespace fresco
