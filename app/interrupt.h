// Ctrl-C (SIGINT) and SIGTERM during long work (`fresco run`, `synth`, `bench`). The handler
// only records the signal (nothing else is safe in a handler); the verbs' loops check
// Interrupted() between frames, stop, drop what they staged, and exit 128 + the signal's
// number with a message saying what was kept. Outputs are only ever replaced whole (temp
// file + rename, StagedFolder), so an interrupted verb leaves the earlier outputs or none.
// A second signal of the same kind ends the process at once (the default action).
#pragma once

#include <string>

namespace fresco {

// Installs the handlers for its lifetime (the earlier ones come back afterwards) and clears
// the recorded signal. One at a time.
class InterruptCatcher {
 public:
  InterruptCatcher();
  ~InterruptCatcher();
  InterruptCatcher(const InterruptCatcher&) = delete;
  InterruptCatcher& operator=(const InterruptCatcher&) = delete;
};

// True once SIGINT or SIGTERM arrived while an InterruptCatcher was alive.
bool Interrupted();
// "SIGINT" or "SIGTERM" ("" when none arrived).
std::string InterruptSignalName();
// 128 + the signal's number (130 for SIGINT, 143 for SIGTERM), the shell's convention.
int InterruptExitCode();

}  // namespace fresco
