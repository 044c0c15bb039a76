// Writes files so that a reader never sees a half-written one: write to a temp file beside
// the target, flush, then rename over it. On failure the previous file (if any) is intact.
// Failures to write (and to make folders) are output errors (StatusKind::kOutput); failures
// to read are bad input.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "pipeline/core/status.h"

namespace fresco {

Status WriteFileAtomic(const std::string& path, const std::string& contents);
// Calls `write(temp_path)` to produce the file, then renames temp_path to `path`. A
// bad-input Status from `write` is returned as an output error (internal ones stay so).
Status WriteFileAtomicWith(const std::string& path,
                           const std::function<Status(const std::string& temp_path)>& write);
Status ReadFileToString(const std::string& path, std::string* contents);
// Creates the folder and its parents; an error names the folder and is bad input (the
// folder asked for cannot be made: exit 2, as a bad --out).
Status MakeDirectories(const std::string& path);

// A folder filled under a hidden name beside `target` (".NAME.partial-XXXXXX") and swapped
// in whole by Commit(): until then `target` keeps its earlier content, and a StagedFolder
// destroyed without Commit() removes what was written into it. So a run that fails or is
// interrupted half-way leaves the earlier folder (or none), never a mix.
class StagedFolder {
 public:
  StagedFolder() = default;
  StagedFolder(const StagedFolder&) = delete;
  StagedFolder& operator=(const StagedFolder&) = delete;
  ~StagedFolder();  // removes the staging folder unless committed

  // Makes the staging folder (and `target`'s parent). Staging folders of the same target
  // left by a killed process are removed first. Errors name the folder.
  Status Open(const std::string& target);
  // Where to write; "" before Open().
  const std::string& path() const { return staging_; }
  // Replaces `target` and everything in it with the staging folder (one atomic exchange
  // where the file system supports it).
  Status Commit();

 private:
  std::string target_, staging_;
  bool committed_ = false;
};

// Moves every file of `from_dir` into `to_dir` (renames, replacing files of the same name),
// the names in `last` after all others, in that order: a reader that waits for the last file
// finds the others complete. Sub-folders are not moved. Both folders must be on one file
// system (e.g. a StagedFolder inside `to_dir`).
Status MoveFilesInto(const std::string& from_dir, const std::string& to_dir,
                     const std::vector<std::string>& last);

}  // namespace fresco
