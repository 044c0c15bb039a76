#include "app/interrupt.h"

#include <signal.h>

#include <atomic>

namespace fresco {
namespace {

// Lock-free, so safe to store from a signal handler.
std::atomic<int> g_signal{0};
static_assert(std::atomic<int>::is_always_lock_free);

struct sigaction g_previous_int, g_previous_term;

extern "C" void RecordSignal(int signal_number) { g_signal.store(signal_number); }

}  // namespace

InterruptCatcher::InterruptCatcher() {
  g_signal.store(0);
  struct sigaction action = {};
  action.sa_handler = RecordSignal;
  sigemptyset(&action.sa_mask);
  // SA_RESTART: system calls in flight (file reads, writes) go on rather than fail with EINTR.
  // SA_RESETHAND: the handler is used once; a second Ctrl-C kills as usual.
  action.sa_flags = SA_RESTART | SA_RESETHAND;
  sigaction(SIGINT, &action, &g_previous_int);
  sigaction(SIGTERM, &action, &g_previous_term);
  // A shell starts background jobs with SIGINT ignored (Ctrl-C is not for them): keep that.
  if (g_previous_int.sa_handler == SIG_IGN) sigaction(SIGINT, &g_previous_int, nullptr);
}

InterruptCatcher::~InterruptCatcher() {
  sigaction(SIGINT, &g_previous_int, nullptr);
  sigaction(SIGTERM, &g_previous_term, nullptr);
}

bool Interrupted() { return g_signal.load() != 0; }

std::string InterruptSignalName() {
  switch (g_signal.load()) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    default:
      return "";
  }
}

int InterruptExitCode() { return 128 + g_signal.load(); }

}  // namespace fresco
