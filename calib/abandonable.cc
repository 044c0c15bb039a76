#include "calib/abandonable.h"

#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>

namespace fresco::calib {
namespace {

Status InThisProcess(const std::function<bool(std::string*)>& work, std::string* bytes) {
  bytes->clear();
  if (work(bytes)) return Status::Ok();
  return Status::Error(*bytes);
}

bool WriteAll(int fd, const char* data, size_t size) {
  for (size_t done = 0; done < size;) {
    const ssize_t n = write(fd, data + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<size_t>(n);
  }
  return true;
}

}  // namespace

Status RunAbandonably(const char* what, const std::function<bool(std::string* bytes)>& work,
                      const std::function<bool()>& cancelled, std::string* bytes) {
  int fds[2];
  if (pipe(fds) != 0) return InThisProcess(work, bytes);
  const pid_t child = fork();
  if (child < 0) {
    close(fds[0]), close(fds[1]);
    return InThisProcess(work, bytes);
  }
  if (child == 0) {  // the work, and a status byte and its result down the pipe; no exit handlers
    close(fds[0]);
    std::string result;
    const char ok = work(&result) ? 1 : 0;
    const bool written = WriteAll(fds[1], &ok, 1) && WriteAll(fds[1], result.data(), result.size());
    _exit(written ? 0 : 1);
  }
  close(fds[1]);
  std::string result;
  bool abandoned = false;
  for (;;) {
    pollfd ready{fds[0], POLLIN, 0};
    const int polled = poll(&ready, 1, 100);
    if (polled == 0 || (polled < 0 && errno == EINTR)) {
      if (cancelled()) {
        kill(child, SIGKILL);
        abandoned = true;
        break;
      }
      continue;
    }
    char chunk[65536];
    const ssize_t n = read(fds[0], chunk, sizeof(chunk));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;  // the end: the child wrote all it had
    result.append(chunk, static_cast<size_t>(n));
  }
  close(fds[0]);
  while (waitpid(child, nullptr, 0) < 0 && errno == EINTR) {
  }
  if (abandoned) return Status::Error("cancelled");
  if (result.empty())
    return Status::Error(std::string(what) + ": the process ended without its result");
  bytes->assign(result, 1);
  if (result[0] != 1) return Status::Error(*bytes);
  return Status::Ok();
}

}  // namespace fresco::calib
