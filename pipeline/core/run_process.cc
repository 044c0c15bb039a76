#include "pipeline/core/run_process.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <sstream>

namespace fresco {

std::string ShellQuote(const std::string& arg) {
  if (!arg.empty() && arg.find_first_of(" \t\n\"'\\$`;&|<>()*?[]{}~#!") == std::string::npos)
    return arg;
  std::string out = "'";
  for (char c : arg) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string FindProgram(const std::string& name) {
  if (name.empty()) return "";
  if (name.find('/') != std::string::npos) {
    return access(name.c_str(), X_OK) == 0 ? name : "";
  }
  const char* path_env = std::getenv("PATH");
  std::stringstream path(path_env ? path_env : "/usr/local/bin:/usr/bin:/bin");
  std::string folder;
  while (std::getline(path, folder, ':')) {
    if (folder.empty()) folder.assign(1, '.');  // (not = ".": GCC 12 -Wrestrict noise)
    std::string candidate = folder;
    candidate += '/';
    candidate += name;
    if (access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return "";
}

Status RunProcess(const std::vector<std::string>& argv, const std::string& log_path, int* exit_code,
                  const std::atomic<bool>* cancel) {
  if (argv.empty()) return Status::Error("RunProcess: empty command");
  const int log_fd = open(log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (log_fd < 0) {
    return Status::Error(log_path + ": cannot open log: " + std::strerror(errno));
  }
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  // The exec error is reported through a pipe closed on a successful exec.
  int error_pipe[2];
  if (pipe2(error_pipe, O_CLOEXEC) != 0) {
    close(log_fd);
    return Status::Error(argv[0] + ": cannot create a pipe: " + std::strerror(errno));
  }
  const pid_t pid = fork();
  if (pid < 0) {
    close(log_fd), close(error_pipe[0]), close(error_pipe[1]);
    return Status::Error(argv[0] + ": cannot fork: " + std::strerror(errno));
  }
  if (pid == 0) {
    close(error_pipe[0]);
    const int null_fd = open("/dev/null", O_RDONLY);
    if (null_fd >= 0) dup2(null_fd, STDIN_FILENO);
    dup2(log_fd, STDOUT_FILENO);
    dup2(log_fd, STDERR_FILENO);
    execvp(args[0], args.data());
    const int error = errno;
    (void)!write(error_pipe[1], &error, sizeof(error));
    _exit(127);
  }
  close(log_fd);
  close(error_pipe[1]);
  int exec_errno = 0;
  const ssize_t got = read(error_pipe[0], &exec_errno, sizeof(exec_errno));
  close(error_pipe[0]);
  int status = 0;
  if (cancel) {
    // Polled, so that a cancel stops the program within 0.1 s.
    int polls_since_term = -1;
    while (true) {
      const pid_t done = waitpid(pid, &status, WNOHANG);
      if (done == pid || (done < 0 && errno != EINTR)) break;
      if (*cancel && polls_since_term < 0) {
        kill(pid, SIGTERM);
        polls_since_term = 0;
      } else if (polls_since_term >= 0 && ++polls_since_term == 20) {
        kill(pid, SIGKILL);
      }
      usleep(100000);
    }
  } else {
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
  }
  if (got == static_cast<ssize_t>(sizeof(exec_errno))) {
    return Status::Error(argv[0] + ": cannot run: " + std::strerror(exec_errno));
  }
  *exit_code =
      WIFEXITED(status) ? WEXITSTATUS(status) : (WIFSIGNALED(status) ? 128 + WTERMSIG(status) : 1);
  return Status::Ok();
}

}  // namespace fresco
