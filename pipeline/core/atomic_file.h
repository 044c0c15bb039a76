// Writes files so that a reader never sees a half-written one: write to a temp file beside
// the target, flush, then rename over it. On failure the previous file (if any) is intact.
#pragma once

#include <functional>
#include <string>

#include "pipeline/core/status.h"

namespace fresco {

Status WriteFileAtomic(const std::string& path, const std::string& contents);
// Calls `write(temp_path)` to produce the file, then renames temp_path to `path`.
Status WriteFileAtomicWith(const std::string& path,
                           const std::function<Status(const std::string& temp_path)>& write);
Status ReadFileToString(const std::string& path, std::string* contents);
// Creates the folder and its parents; error names the folder.
Status MakeDirectories(const std::string& path);

}  // namespace fresco
