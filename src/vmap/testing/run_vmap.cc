#include "vmap/testing/run_vmap.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <utility>

extern char** environ;

namespace vmap::testing {
namespace {
// Begins the line GNU time adds to a bounded run's output: the peak memory (KB), user and system CPU seconds.
constexpr char kUsageMarker[] = "vmap-testing-usage:";
}  // namespace

std::filesystem::path VmapBinary() { return VMAP_BINARY; }

std::string Quote(const std::filesystem::path& text) {
  std::string quoted = "'";
  for (char c : text.string()) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

CliResult RunVmap(const std::string& arguments, const std::string& environment) {
  const std::string command = environment + " " + Quote(VmapBinary()) + " " + arguments + " 2>&1";
  CliResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return result;
  char buffer[4096];
  while (size_t n = fread(buffer, 1, sizeof(buffer), pipe)) result.output.append(buffer, n);
  const int status = pclose(pipe);
  result.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

int RunVmap(const std::string& arguments, std::string* output) {
  CliResult result = RunVmap(arguments, "");
  if (output) *output = std::move(result.output);
  return result.status;
}

BoundedRun RunVmapBounded(const std::vector<std::string>& arguments, double timeout_seconds) {
  return RunBounded(VmapBinary(), arguments, timeout_seconds);
}

BoundedRun RunBounded(const std::filesystem::path& binary, const std::vector<std::string>& arguments,
                      double timeout_seconds, const std::vector<std::string>& environment) {
  BoundedRun run;
  std::vector<std::string> variables = environment;
  for (char** variable = environ; *variable; ++variable) variables.push_back(*variable);  // the first one wins
  std::vector<char*> envp;
  for (std::string& v : variables) envp.push_back(v.data());
  envp.push_back(nullptr);
  // Through GNU time, which forks the binary from a small process of its own: a child spawned from here would report
  // as its peak this process's (exec records the memory it replaces, and posix_spawn's child shares this process's
  // until it execs), which in a test binary that ran other tests before may be hundreds of MB.
  std::vector<std::string> storage = {"/usr/bin/time", "-q", "-f", std::string("\n") + kUsageMarker + " %M %U %S",
                                      binary.string()};
  storage.insert(storage.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (std::string& a : storage) argv.push_back(a.data());
  argv.push_back(nullptr);
  int pipe_fds[2];
  if (pipe2(pipe_fds, O_CLOEXEC) != 0) return run;
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_adddup2(&files, pipe_fds[1], 1);
  posix_spawn_file_actions_adddup2(&files, pipe_fds[1], 2);
  // A process group of its own: a run past its time is killed with whatever it started (GNU time's child).
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  posix_spawnattr_setpgroup(&attributes, 0);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
  pid_t pid = -1;
  const int spawned = posix_spawn(&pid, argv[0], &files, &attributes, argv.data(), envp.data());
  posix_spawnattr_destroy(&attributes);
  posix_spawn_file_actions_destroy(&files);
  close(pipe_fds[1]);
  if (spawned != 0) {
    close(pipe_fds[0]);
    return run;
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_seconds);
  char buffer[4096];
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      run.timed_out = true;
      kill(-pid, SIGKILL);
      break;
    }
    pollfd readable{pipe_fds[0], POLLIN, 0};
    if (poll(&readable, 1, static_cast<int>(std::min<long>(left.count(), 1000))) <= 0) continue;
    const ssize_t n = read(pipe_fds[0], buffer, sizeof buffer);
    if (n <= 0) break;  // the child closed its output: it ends
    run.output.append(buffer, static_cast<size_t>(n));
  }
  close(pipe_fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  const size_t usage_line = run.output.rfind(std::string("\n") + kUsageMarker + " ");
  if (usage_line != std::string::npos) {
    long peak_kb = 0;
    double user_seconds = 0, system_seconds = 0;
    std::sscanf(run.output.c_str() + usage_line + 1 + std::strlen(kUsageMarker), "%ld %lf %lf", &peak_kb, &user_seconds,
                &system_seconds);
    run.max_rss_bytes = peak_kb * 1024L;
    run.cpu_seconds = user_seconds + system_seconds;
    run.output.erase(usage_line);
  }
  // GNU time exits with the binary's status, or 128 + the signal that ended it.
  run.status = !run.timed_out && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (run.timed_out) run.output += "\n(timed out after " + std::to_string(timeout_seconds) + " s)";
  return run;
}

BackgroundVmap::BackgroundVmap(const std::vector<std::string>& arguments, const std::filesystem::path& log,
                               const std::filesystem::path& binary) {
  std::vector<std::string> storage = {binary.empty() ? VmapBinary().string() : binary.string()};
  storage.insert(storage.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (std::string& a : storage) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t defaults, empty;
  sigemptyset(&defaults);
  for (int s : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&defaults, s);
  sigemptyset(&empty);
  posix_spawnattr_setsigdefault(&attributes, &defaults);
  posix_spawnattr_setsigmask(&attributes, &empty);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&files, 1, 2);
  pid_t pid = -1;
  if (posix_spawn(&pid, argv[0], &files, &attributes, argv.data(), environ) == 0) pid_ = pid;
  posix_spawn_file_actions_destroy(&files);
  posix_spawnattr_destroy(&attributes);
}

BackgroundVmap::~BackgroundVmap() {
  if (pid_ > 0 && !waited_) {
    kill(pid_, SIGKILL);
    Wait();
  }
}

void BackgroundVmap::Signal(int signal_number) const {
  if (pid_ > 0) kill(pid_, signal_number);
}

bool BackgroundVmap::Running() const {
  if (pid_ <= 0 || waited_) return false;
  siginfo_t info{};
  return waitid(P_PID, pid_, &info, WEXITED | WNOHANG | WNOWAIT) == 0 && info.si_pid == 0;
}

int BackgroundVmap::Wait() {
  if (pid_ <= 0) return -1;
  int status = 0;
  waitpid(pid_, &status, 0);
  waited_ = true;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace vmap::testing
