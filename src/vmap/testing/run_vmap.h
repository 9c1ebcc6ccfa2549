#pragma once
// Running the vmap binary as a user does, from tests.

#include <filesystem>
#include <string>

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

}  // namespace vmap::testing
