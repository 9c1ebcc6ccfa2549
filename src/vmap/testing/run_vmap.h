#pragma once
// Running the vmap binary as a user does, from tests.

#include <filesystem>
#include <string>
#include <vector>

namespace vmap::testing {

// The vmap binary of this build (CMake's VMAP_BINARY).
std::filesystem::path VmapBinary();

// `text` quoted for a POSIX shell command line (single quotes; a quote inside is escaped).
std::string Quote(const std::filesystem::path& text);

struct CliResult {
  int status = -1;     // exit status; -1 when it did not exit normally
  std::string output;  // stdout and stderr together
};

// The vmap binary run with `arguments` (a shell command line: quote paths with Quote()); `environment` is
// prepended (VAR=value ...).
CliResult RunVmap(const std::string& arguments, const std::string& environment = "");

// The same, in the form most tests assert with: returns the exit status and stores the output in `*output`.
int RunVmap(const std::string& arguments, std::string* output);

// The binary run with `arguments` (no shell: one argument each) for at most `timeout_seconds`: a run still going
// then is killed and reported as timed out (status -1); a run a signal ended has status 128 + the signal. Its own
// peak memory (maximum resident set) and CPU time, measured by GNU time (/usr/bin/time): what hostile inputs may
// cost, asserted by the tests of issue 38.
struct BoundedRun {
  int status = -1;
  bool timed_out = false;
  long max_rss_bytes = 0;
  double cpu_seconds = 0;  // user and system
  std::string output;      // stdout and stderr together
};
BoundedRun RunVmapBounded(const std::vector<std::string>& arguments, double timeout_seconds);
// The same for any `binary` (another build of vmap: bench/hostile_bench compares two), with `environment`
// ("TMPDIR=/x", ...) added to this process's.
BoundedRun RunBounded(const std::filesystem::path& binary, const std::vector<std::string>& arguments,
                      double timeout_seconds, const std::vector<std::string>& environment = {});

// The binary started in the background as from a terminal (SIGINT, SIGTERM and SIGHUP at their defaults,
// whatever the test runner inherited), its output in the file `log`; killed (SIGKILL) if still running when
// destroyed. `binary` is another build of vmap when given (bench/hostile_bench).
class BackgroundVmap {
 public:
  BackgroundVmap(const std::vector<std::string>& arguments, const std::filesystem::path& log,
                 const std::filesystem::path& binary = {});
  ~BackgroundVmap();
  BackgroundVmap(const BackgroundVmap&) = delete;
  BackgroundVmap& operator=(const BackgroundVmap&) = delete;

  void Signal(int signal_number) const;
  // Whether it has not exited yet (it is not reaped).
  bool Running() const;
  // The exit status, or 128 + the signal that ended it. (Its peak memory is not measured: spawned from here, its
  // peak would be this process's; RunVmapBounded measures a run's own.)
  int Wait();

 private:
  int pid_ = -1;
  bool waited_ = false;
};

}  // namespace vmap::testing
