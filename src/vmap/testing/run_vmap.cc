#include "vmap/testing/run_vmap.h"

#include <sys/wait.h>

#include <cstdio>
#include <utility>

namespace vmap::testing {

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

}  // namespace vmap::testing
