#include "pipeline/core/atomic_file.h"

#include <fcntl.h>
#include <stdio.h>  // renameat2, RENAME_EXCHANGE (glibc >= 2.28)
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>
#include <vector>

namespace fresco {
namespace {

namespace fs = std::filesystem;

std::string ErrnoText(int error) { return std::strerror(error); }

// The folder that holds `path` ("." for a bare file name).
std::string ParentFolder(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  return parent.empty() ? std::string(".") : parent.string();
}

// Makes an empty temp file beside `path`, named ".NAME.tmp-XXXXXX.EXT": hidden, in the same
// folder (so the rename is atomic) and with the target's extension (so writers that pick the
// format by extension, e.g. cv::imwrite, still work).
Status MakeTempFile(const std::string& path, std::string* temp_path) {
  const fs::path target(path);
  if (target.filename().empty()) return Status::OutputError(path + ": not a file name");
  const std::string extension = target.extension().string();
  const std::string stem = target.filename().string();
  std::string pattern = (target.parent_path() / ("." + stem + ".tmp-XXXXXX" + extension)).string();
  const int fd = mkstemps(pattern.data(), static_cast<int>(extension.size()));
  if (fd < 0) {
    const int error = errno;
    return Status::OutputError(path + ": cannot create a temp file in " + ParentFolder(path) +
                               ": " + ErrnoText(error));
  }
  // mkstemps makes the file 0600; give it the mode the target has, or 0644 for a new file.
  struct stat target_stat;
  const mode_t mode = stat(path.c_str(), &target_stat) == 0 ? (target_stat.st_mode & 07777) : 0644;
  fchmod(fd, mode);
  close(fd);
  *temp_path = pattern;
  return Status::Ok();
}

// Flushes a file's data to disk.
Status SyncFile(const std::string& file, const std::string& path_for_messages) {
  const int fd = open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    const int error = errno;
    return Status::OutputError(path_for_messages +
                               ": cannot reopen the written temp file: " + ErrnoText(error));
  }
  const int rc = fsync(fd);
  const int error = errno;
  close(fd);
  if (rc != 0)
    return Status::OutputError(path_for_messages + ": fsync failed: " + ErrnoText(error));
  return Status::Ok();
}

// Flushes the folder entry after a rename (best effort: some file systems refuse).
void SyncFolder(const std::string& folder) {
  const int fd = open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  fsync(fd);
  close(fd);
}

Status WriteAll(const std::string& file, const std::string& contents,
                const std::string& path_for_messages) {
  const int fd = open(file.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
  if (fd < 0) {
    const int error = errno;
    return Status::OutputError(path_for_messages +
                               ": cannot open for writing: " + ErrnoText(error));
  }
  size_t written = 0;
  while (written < contents.size()) {
    const ssize_t n = write(fd, contents.data() + written, contents.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int error = errno;
      close(fd);
      return Status::OutputError(path_for_messages + ": write failed: " + ErrnoText(error));
    }
    written += static_cast<size_t>(n);
  }
  if (close(fd) != 0) {
    const int error = errno;
    return Status::OutputError(path_for_messages + ": write failed: " + ErrnoText(error));
  }
  return Status::Ok();
}

}  // namespace

Status WriteFileAtomicWith(const std::string& path,
                           const std::function<Status(const std::string& temp_path)>& write) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) return Status::OutputError(path + ": is a folder, not a file");
  std::string temp_path;
  FRESCO_RETURN_IF_ERROR(MakeTempFile(path, &temp_path));
  auto fail = [&](const Status& status) {
    std::remove(temp_path.c_str());
    return status;
  };
  Status written;
  try {
    written = write(temp_path).Reclassified(StatusKind::kOutput);  // failing here: output
  } catch (const std::exception& e) {
    written = Status::OutputError(path + ": writing failed: " + e.what());
  }
  if (!written.ok()) return fail(written);
  if (!fs::is_regular_file(temp_path, ec)) {
    return fail(Status::OutputError(path + ": the writer produced no file"));
  }
  Status synced = SyncFile(temp_path, path);
  if (!synced.ok()) return fail(synced);
  if (std::rename(temp_path.c_str(), path.c_str()) != 0) {
    const int error = errno;
    return fail(
        Status::OutputError(path + ": cannot rename the temp file over it: " + ErrnoText(error)));
  }
  SyncFolder(ParentFolder(path));
  return Status::Ok();
}

Status WriteFileAtomic(const std::string& path, const std::string& contents) {
  return WriteFileAtomicWith(
      path, [&](const std::string& temp_path) { return WriteAll(temp_path, contents, path); });
}

Status ReadFileToString(const std::string& path, std::string* contents) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return Status::Error(path + ": no such file");
  if (fs::is_directory(path, ec)) return Status::Error(path + ": is a folder, not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int error = errno;
    return Status::Error(path + ": cannot open: " + ErrnoText(error));
  }
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) return Status::Error(path + ": read failed");
  *contents = buffer.str();
  return Status::Ok();
}

Status MakeDirectories(const std::string& path) {
  if (path.empty()) return Status::Ok();
  std::error_code ec;
  if (fs::is_directory(path, ec)) return Status::Ok();
  if (fs::exists(path, ec)) return Status::Error(path + ": exists and is not a folder");
  fs::create_directories(path, ec);
  if (ec) return Status::Error(path + ": cannot create folder: " + ec.message());
  return Status::Ok();
}

StagedFolder::~StagedFolder() {
  if (staging_.empty() || committed_) return;
  std::error_code ec;
  fs::remove_all(staging_, ec);
}

Status StagedFolder::Open(const std::string& target) {
  const fs::path path = fs::path(target).lexically_normal();
  const std::string name = path.filename().string();
  if (name.empty() || name == "." || name == "..")
    return Status::OutputError(target + ": not a folder name");
  const fs::path parent = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  FRESCO_RETURN_IF_ERROR(MakeDirectories(parent.string()));
  std::error_code ec;
  if (fs::exists(path, ec) && !fs::is_directory(path, ec))
    return Status::OutputError(target + ": exists and is not a folder");
  // Leftovers of a process killed before it could clean up (SIGKILL, power loss).
  const std::string prefix = "." + name + ".partial-";
  for (const auto& entry : fs::directory_iterator(parent, ec)) {
    const std::string entry_name = entry.path().filename().string();
    if (entry_name.rfind(prefix, 0) == 0 && entry.is_directory(ec))
      fs::remove_all(entry.path(), ec);
  }
  std::string pattern = (parent / (prefix + "XXXXXX")).string();
  if (!mkdtemp(pattern.data())) {
    const int error = errno;
    return Status::OutputError(target + ": cannot create a staging folder in " + parent.string() +
                               ": " + ErrnoText(error));
  }
  chmod(pattern.c_str(), 0755);  // mkdtemp makes it 0700
  target_ = path.string();
  staging_ = pattern;
  committed_ = false;
  return Status::Ok();
}

Status StagedFolder::Commit() {
  if (staging_.empty() || committed_)
    return Status::Internal(target_ + ": nothing staged to commit");
  std::error_code ec;
  if (!fs::exists(target_, ec)) {
    if (std::rename(staging_.c_str(), target_.c_str()) != 0) {
      const int error = errno;
      return Status::OutputError(target_ +
                                 ": cannot rename the staging folder to it: " + ErrnoText(error));
    }
  } else if (renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, target_.c_str(), RENAME_EXCHANGE) !=
             0) {
    // No atomic exchange on this file system: move the old folder aside, then rename.
    std::string aside = staging_ + "-old";
    if (std::rename(target_.c_str(), aside.c_str()) != 0 ||
        std::rename(staging_.c_str(), target_.c_str()) != 0) {
      const int error = errno;
      return Status::OutputError(
          target_ + ": cannot replace it with the staging folder: " + ErrnoText(error));
    }
    fs::remove_all(aside, ec);
  }
  committed_ = true;
  // After an exchange the staging name holds the earlier folder.
  fs::remove_all(staging_, ec);
  SyncFolder(ParentFolder(target_));
  return Status::Ok();
}

Status MoveFilesInto(const std::string& from_dir, const std::string& to_dir,
                     const std::vector<std::string>& last) {
  std::error_code ec;
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(from_dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file(ec) && std::find(last.begin(), last.end(), name) == last.end())
      names.push_back(name);
  }
  if (ec) return Status::OutputError(from_dir + ": cannot list it: " + ec.message());
  for (const std::string& name : last)
    if (fs::exists(fs::path(from_dir) / name, ec)) names.push_back(name);
  for (const std::string& name : names) {
    const std::string from = (fs::path(from_dir) / name).string();
    const std::string to = (fs::path(to_dir) / name).string();
    if (std::rename(from.c_str(), to.c_str()) != 0) {
      const int error = errno;
      return Status::OutputError(to +
                                 ": cannot move the written file into place: " + ErrnoText(error));
    }
  }
  SyncFolder(to_dir);
  return Status::Ok();
}

}  // namespace fresco
