#include "tests/test_support.h"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>

namespace fresco::testing {
namespace fs = std::filesystem;

std::string SharedDataDir() {
  const char* env = std::getenv("FRESCO_SHARED_DATA");
  const std::string dir = env ? env : "";
  if (dir.empty() || !fs::is_directory(dir)) return "";
  return fs::canonical(dir).string();
}

std::string SourceDir() {
  const char* env = std::getenv("FRESCO_SOURCE_DIR");
  if (env) return env;
#ifdef FRESCO_TEST_SOURCE_DIR
  return FRESCO_TEST_SOURCE_DIR;  // as CMake knows it, when run outside CTest
#else
  return ".";
#endif
}

namespace {
std::vector<std::string>& TempDirs() {
  static std::vector<std::string> dirs;
  return dirs;
}
void RemoveTempDirs() {
  if (std::getenv("FRESCO_KEEP_TEST_FILES")) return;
  std::error_code ec;
  for (const auto& d : TempDirs()) fs::remove_all(d, ec);
}
}  // namespace

std::string MakeTempDir(const std::string& tag) {
  static std::once_flag once;
  std::call_once(once, [] {
    TempDirs();
    std::atexit(RemoveTempDirs);
  });  // list outlives it
  std::string pattern = (fs::temp_directory_path() / ("fresco-" + tag + "-XXXXXX")).string();
  char* made = mkdtemp(pattern.data());
  if (!made) throw std::runtime_error("mkdtemp failed for " + pattern);
  TempDirs().push_back(made);
  return made;
}

void WriteText(const std::string& path, const std::string& text) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream out(path, std::ios::binary);
  out << text;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

StartedCommand StartFresco(const std::vector<std::string>& args, long long address_space_bytes) {
  const char* env = std::getenv("FRESCO_BINARY");
#ifdef FRESCO_TEST_BINARY
  const std::string binary = env ? env : FRESCO_TEST_BINARY;  // as CMake knows it
#else
  const std::string binary = env ? env : "build/app/fresco";
#endif
  const std::string dir = MakeTempDir("cmd");
  StartedCommand command;
  command.out_path = dir + "/stdout";
  command.err_path = dir + "/stderr";
  pid_t pid = fork();
  if (pid == 0) {
    int out_fd = open(command.out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    int err_fd = open(command.err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    int null_fd = open("/dev/null", O_RDONLY);
    dup2(out_fd, 1);
    dup2(err_fd, 2);
    dup2(null_fd, 0);
    if (address_space_bytes > 0) {
      const rlimit limit{static_cast<rlim_t>(address_space_bytes),
                         static_cast<rlim_t>(address_space_bytes)};
      setrlimit(RLIMIT_AS, &limit);
    }
    // "--xvfb" first: run under xvfb-run with a 1600x1000 screen (GUI tests).
    const bool xvfb = !args.empty() && args[0] == "--xvfb";
    static const std::string kXvfb = "/usr/bin/xvfb-run", kA = "-a", kS = "-s",
                             kScreen = "-screen 0 1600x1000x24";
    std::vector<char*> argv;
    if (xvfb)
      for (const std::string* a : {&kXvfb, &kA, &kS, &kScreen})
        argv.push_back(const_cast<char*>(a->c_str()));
    argv.push_back(const_cast<char*>(binary.c_str()));
    for (size_t i = xvfb ? 1 : 0; i < args.size(); ++i)
      argv.push_back(const_cast<char*>(args[i].c_str()));
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  command.pid = pid;
  return command;
}

CommandResult WaitFresco(const StartedCommand& command) {
  CommandResult result;
  int status = 0;
  waitpid(command.pid, &status, 0);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  result.out = ReadText(command.out_path);
  result.err = ReadText(command.err_path);
  return result;
}

CommandResult RunFresco(const std::vector<std::string>& args) {
  return WaitFresco(StartFresco(args));
}

}  // namespace fresco::testing
