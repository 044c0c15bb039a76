// `fresco gui ARGS...`: starts the authoring app, the `fresco-gui` executable next to this
// one (CONTRACT.md allows a second executable), in place of this process: same arguments,
// same stdout and stderr, its exit code. The `fresco` CLI itself links no GL, GLFW or ImGui
// and so runs on headless machines without them.
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <iostream>

#include "app/commands.h"

namespace fresco {

int RunVerbGui(const CommandArgs& args) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  const std::string gui =
      (ec ? fs::path("fresco-gui") : self.parent_path() / "fresco-gui").string();
  if (!fs::exists(gui, ec)) {
    std::cerr << "fresco gui: this build has no GUI (" << gui
              << " is missing: configure with -DFRESCO_GUI=ON)\n";
    return kExitFailure;
  }
  std::vector<std::string> strings = {gui};
  strings.insert(strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& s : strings) argv.push_back(s.data());
  argv.push_back(nullptr);
  std::cout.flush();
  std::cerr.flush();
  execv(gui.c_str(), argv.data());
  std::cerr << "fresco gui: cannot start " << gui << ": " << std::strerror(errno) << "\n";
  return kExitFailure;
}

}  // namespace fresco
