#include "vmap/core/interrupt.h"

#include <pthread.h>
#include <signal.h>
#include <string.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <thread>

#include "vmap/core/atomic_output.h"

namespace vmap {
namespace {

constexpr int kHandledSignals[] = {SIGINT, SIGTERM, SIGHUP};

std::atomic<bool> end_input_on_sigint{false};
std::atomic<bool> input_end_requested{false};

// Runs on the watcher thread, never in a signal handler.
[[noreturn]] void EndInterruptedProcess(int signal_number) {
  const int removed = RemoveTemporaryOutputsForExit();
  std::fprintf(stderr, "\nvmap: interrupted (%s)%s\n", strsignal(signal_number),
               removed > 0 ? "; its unfinished outputs were removed" : "");
  std::fflush(stderr);
  _exit(128 + signal_number);
}

}  // namespace

void EndInputOnSigint(bool enabled) {
  input_end_requested = false;
  end_input_on_sigint = enabled;
}

bool InputEndRequested() { return input_end_requested; }

void InstallInterruptHandling() {
  sigset_t signals;
  sigemptyset(&signals);
  bool any = false;
  for (int signal_number : kHandledSignals) {
    struct sigaction current;
    if (sigaction(signal_number, nullptr, &current) == 0 && current.sa_handler == SIG_IGN) continue;
    sigaddset(&signals, signal_number);
    any = true;
  }
  if (!any) return;
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  // Detached: it waits until the process ends, and must not hold up exit().
  std::thread([signals] {
    for (;;) {
      int signal_number = 0;
      if (sigwait(&signals, &signal_number) != 0) continue;
      // The first SIGINT of a live run ends its input; the run then finishes and exits on its own.
      if (signal_number == SIGINT && end_input_on_sigint && !input_end_requested.exchange(true)) {
        std::fprintf(stderr, "\nvmap: interrupted: finishing the map from the frames seen (again to abort)\n");
        std::fflush(stderr);
        continue;
      }
      EndInterruptedProcess(signal_number);
    }
  }).detach();
}

}  // namespace vmap
