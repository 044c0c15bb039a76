// Work that cannot be stopped from inside (a library call with no hook to stop it: mrcal's
// optimisation, OpenCV's calibrateCamera) run so that it can be abandoned: in a child process
// that sends its result back as bytes through a pipe. While it runs `cancelled` is asked every
// 0.1 s; when it says so the child is killed and the call returns "cancelled" at once.
#pragma once

#include <functional>
#include <string>

#include "pipeline/core/status.h"

namespace fresco::calib {

// Runs `work` (in a child process; in this one when no child can be made): it appends its
// result to `bytes` and returns true, or returns false with its error message in `bytes`.
// Returns its result in `bytes`; an error with the work's message when it failed,
// "cancelled" when abandoned, and "`what`: the process ended without its result" when the
// child died.
Status RunAbandonably(const char* what, const std::function<bool(std::string* bytes)>& work,
                      const std::function<bool()>& cancelled, std::string* bytes);

}  // namespace fresco::calib
