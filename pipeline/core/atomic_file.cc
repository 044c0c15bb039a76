#include "pipeline/core/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
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
  if (target.filename().empty()) return Status::Error(path + ": not a file name");
  const std::string extension = target.extension().string();
  const std::string stem = target.filename().string();
  std::string pattern = (target.parent_path() / ("." + stem + ".tmp-XXXXXX" + extension)).string();
  const int fd = mkstemps(pattern.data(), static_cast<int>(extension.size()));
  if (fd < 0) {
    const int error = errno;
    return Status::Error(path + ": cannot create a temp file in " + ParentFolder(path) + ": " +
                         ErrnoText(error));
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
    return Status::Error(path_for_messages +
                         ": cannot reopen the written temp file: " + ErrnoText(error));
  }
  const int rc = fsync(fd);
  const int error = errno;
  close(fd);
  if (rc != 0) return Status::Error(path_for_messages + ": fsync failed: " + ErrnoText(error));
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
    return Status::Error(path_for_messages + ": cannot open for writing: " + ErrnoText(error));
  }
  size_t written = 0;
  while (written < contents.size()) {
    const ssize_t n = write(fd, contents.data() + written, contents.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int error = errno;
      close(fd);
      return Status::Error(path_for_messages + ": write failed: " + ErrnoText(error));
    }
    written += static_cast<size_t>(n);
  }
  if (close(fd) != 0) {
    const int error = errno;
    return Status::Error(path_for_messages + ": write failed: " + ErrnoText(error));
  }
  return Status::Ok();
}

}  // namespace

Status WriteFileAtomicWith(const std::string& path,
                           const std::function<Status(const std::string& temp_path)>& write) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) return Status::Error(path + ": is a folder, not a file");
  std::string temp_path;
  FRESCO_RETURN_IF_ERROR(MakeTempFile(path, &temp_path));
  auto fail = [&](const Status& status) {
    std::remove(temp_path.c_str());
    return status;
  };
  Status written;
  try {
    written = write(temp_path);
  } catch (const std::exception& e) {
    written = Status::Error(path + ": writing failed: " + e.what());
  }
  if (!written.ok()) return fail(written);
  if (!fs::is_regular_file(temp_path, ec)) {
    return fail(Status::Error(path + ": the writer produced no file"));
  }
  Status synced = SyncFile(temp_path, path);
  if (!synced.ok()) return fail(synced);
  if (std::rename(temp_path.c_str(), path.c_str()) != 0) {
    const int error = errno;
    return fail(Status::Error(path + ": cannot rename the temp file over it: " + ErrnoText(error)));
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

}  // namespace fresco
