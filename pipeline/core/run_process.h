// Runs an external program (no shell) with its stdout and stderr appended to a log file,
// and finds programs on PATH. Used to drive the `colmap` command-line program.
#pragma once

#include <atomic>
#include <string>
#include <vector>

#include "pipeline/core/status.h"

namespace fresco {

// Runs argv[0] (looked up on PATH when it holds no '/') with argv[1..]; waits for it.
// `exit_code` gets its exit status (128 + signal when killed). Error only when it could not
// be started at all (the message names the program and the log). When `cancel` becomes true
// while it runs, the program is sent SIGTERM (then SIGKILL after 2 s) and waited for.
Status RunProcess(const std::vector<std::string>& argv, const std::string& log_path,
                  int* exit_code, const std::atomic<bool>* cancel = nullptr);

// `arg` as one word for bash: as it is when it holds nothing bash would read, else in single
// quotes (for the commands Fresco logs and the job scripts it writes).
std::string ShellQuote(const std::string& arg);

// The absolute path of `name` on PATH (or `name` itself when it holds a '/' and is
// executable); "" when not found.
std::string FindProgram(const std::string& name);

}  // namespace fresco
