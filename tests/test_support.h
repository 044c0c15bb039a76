// Shared helpers for Fresco's tests: where the shared real data is (tests that need it skip
// with a clear message when it is absent), a fresh temp folder per test, and running the
// `fresco` binary as a user would (for CLI and exit-code tests).
#pragma once

#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace fresco::testing {

// ../shared/data, or "" when it is absent.
std::string SharedDataDir();
// The repository root (for projects/).
std::string SourceDir();
// A new empty folder under the system temp dir, removed at process exit unless
// FRESCO_KEEP_TEST_FILES is set.
std::string MakeTempDir(const std::string& tag);
void WriteText(const std::string& path, const std::string& text);
std::string ReadText(const std::string& path);

struct CommandResult {
  int exit_code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};
// Runs build/app/fresco with `args` (no shell quoting issues: args are passed as argv).
// When args[0] is "--xvfb", it runs under /usr/bin/xvfb-run with a 1600x1000 screen.
CommandResult RunFresco(const std::vector<std::string>& args);

// `fresco` started in the background (interrupt tests): its pid and where its stdout and
// stderr go (readable while it runs).
struct StartedCommand {
  int pid = -1;
  std::string out_path, err_path;
};
// `address_space_bytes` > 0: the child's address space is limited to it (RLIMIT_AS), so
// that allocations beyond it fail as they do on a machine out of memory.
StartedCommand StartFresco(const std::vector<std::string>& args,
                           long long address_space_bytes = 0);
// Waits for it to end; exit_code is 128 + the signal when a signal ended it.
CommandResult WaitFresco(const StartedCommand& command);

}  // namespace fresco::testing

// Skips the current test when ../shared/data is absent.
#define FRESCO_REQUIRE_SHARED_DATA()                                                 \
  do {                                                                               \
    if (::fresco::testing::SharedDataDir().empty())                                  \
      GTEST_SKIP() << "../shared/data is absent (a user's clone has none): skipped"; \
  } while (0)
