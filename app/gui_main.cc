// fresco-gui: the authoring app (Dear ImGui + GLFW + OpenGL), a second executable next to
// `fresco`, which starts it for `fresco gui ARGS...` (gui_launcher.cc): the CLI then never
// loads GL. `fresco-gui ARGS...` is the same as `fresco gui ARGS...`.
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "app/gui_command.h"

int main(int argc, char** argv) {
  try {
    return fresco::RunGuiCommand(fresco::CommandArgs(argv + 1, argv + argc));
  } catch (const std::exception& e) {
    std::cerr << "fresco gui: internal error: " << e.what() << "\n";
    return fresco::kExitFailure;
  }
}
