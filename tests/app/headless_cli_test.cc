// The `fresco` CLI links no GL, GLFW or ImGui: headless machines run it without
// them. Its direct shared-library needs hold none of them, while the app's own executable
// next to it, fresco-gui, needs them; `fresco gui` starts fresco-gui with the same
// arguments and passes its exit code on.
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include <gtest/gtest.h>

#include "pipeline/core/run_process.h"
#include "tests/test_support.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;

std::string FrescoBinary() {
  const char* env = std::getenv("FRESCO_BINARY");
  return env ? env : "build/app/fresco";
}

// The NEEDED entries of an ELF file's dynamic section (readelf -d), e.g. "libc.so.6".
std::vector<std::string> NeededLibraries(const std::string& binary) {
  const std::string log = testing::MakeTempDir("readelf") + "/readelf.txt";
  int exit_code = -1;
  const Status s = RunProcess({"readelf", "-d", binary}, log, &exit_code);
  EXPECT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(exit_code, 0);
  std::vector<std::string> needed;
  std::istringstream lines(testing::ReadText(log));
  for (std::string line; std::getline(lines, line);) {
    if (line.find("(NEEDED)") == std::string::npos) continue;
    const size_t open = line.find('['), close = line.find(']');
    if (open != std::string::npos && close > open)
      needed.push_back(line.substr(open + 1, close - open - 1));
  }
  return needed;
}

// Any of the GUI's libraries among `needed`: "" when none.
std::string GuiLibraryIn(const std::vector<std::string>& needed) {
  for (const std::string& lib : needed)
    for (const char* gui : {"libglfw", "libGL", "libOpenGL", "libEGL", "libimgui"})
      if (lib.rfind(gui, 0) == 0) return lib;
  return "";
}

TEST(HeadlessCli, FrescoNeedsNoGlGlfwOrImGui) {
  if (FindProgram("readelf").empty()) GTEST_SKIP() << "readelf (binutils) is not installed";
  const std::vector<std::string> needed = NeededLibraries(FrescoBinary());
  ASSERT_FALSE(needed.empty());  // it reads the section: libc at least
  EXPECT_EQ(GuiLibraryIn(needed), "");
  const std::string gui = (fs::path(FrescoBinary()).parent_path() / "fresco-gui").string();
  if (!fs::exists(gui)) GTEST_SKIP() << "no fresco-gui (configured with -DFRESCO_GUI=OFF)";
  EXPECT_NE(GuiLibraryIn(NeededLibraries(gui)), "");  // the check finds them where they are
}

TEST(HeadlessCli, GuiVerbStartsTheAppWithItsArguments) {
  const std::string gui = (fs::path(FrescoBinary()).parent_path() / "fresco-gui").string();
  if (!fs::exists(gui)) GTEST_SKIP() << "no fresco-gui (configured with -DFRESCO_GUI=OFF)";
  const testing::CommandResult help = testing::RunFresco({"gui", "--help"});
  EXPECT_EQ(help.exit_code, 0) << help.err;
  EXPECT_EQ(help.out.rfind("usage: fresco gui", 0), 0u) << help.out;
  // Bad usage is found by the app's executable: exit 2, before any window opens.
  const testing::CommandResult bad = testing::RunFresco({"gui", "--frames", "0"});
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_NE(bad.err.find("--frames must be >= 1"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace fresco
