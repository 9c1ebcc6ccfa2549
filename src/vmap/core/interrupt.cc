#include "vmap/core/interrupt.h"

#include <pthread.h>
#include <signal.h>
#include <string.h>
#include <unistd.h>

#include <cstdio>
#include <thread>

#include "vmap/core/atomic_output.h"

namespace vmap {
namespace {

constexpr int kHandledSignals[] = {SIGINT, SIGTERM, SIGHUP};

// Runs on the watcher thread, never in a signal handler.
[[noreturn]] void EndInterruptedProcess(int signal_number) {
  const int removed = RemoveTemporaryOutputsForExit();
  std::fprintf(stderr, "\nvmap: interrupted (%s)%s\n", strsignal(signal_number),
               removed > 0 ? "; its unfinished outputs were removed" : "");
  std::fflush(stderr);
  _exit(128 + signal_number);
}

}  // namespace

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
    int signal_number = 0;
    while (sigwait(&signals, &signal_number) != 0) {
    }
    EndInterruptedProcess(signal_number);
  }).detach();
}

}  // namespace vmap
