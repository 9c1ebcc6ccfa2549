#include "vmap/core/temporary_name.h"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <mutex>
#include <random>
#include <regex>

namespace vmap {
namespace fs = std::filesystem;

fs::path TemporarySibling(const fs::path& path, const char* tag) {
  static std::mutex mutex;
  static std::mt19937 random{std::random_device{}()};
  unsigned suffix;
  {
    std::lock_guard<std::mutex> lock(mutex);
    suffix = random() % 1000000;
  }
  const fs::path parent = path.has_parent_path() ? path.parent_path() : fs::path(".");
  return parent /
         ("." + path.filename().string() + "." + tag + "-" + std::to_string(getpid()) + "-" + std::to_string(suffix));
}

namespace {

constexpr const char* kTemporaryTags[] = {"partial", "old", "tmp"};

bool AllDigits(const std::string& text) {
  return !text.empty() && text.size() <= 18 && text.find_first_not_of("0123456789") == std::string::npos;
}

}  // namespace

long TemporaryOwner(const std::string& file_name, const std::string& name) {
  const std::string prefix = "." + name + ".";
  if (file_name.compare(0, prefix.size(), prefix) != 0) return 0;
  const std::string rest = file_name.substr(prefix.size());
  for (const char* tag : kTemporaryTags) {
    const std::string tag_prefix = std::string(tag) + "-";
    if (rest.compare(0, tag_prefix.size(), tag_prefix) != 0) continue;
    const std::string numbers = rest.substr(tag_prefix.size());
    const size_t dash = numbers.find('-');
    if (dash == std::string::npos) return 0;
    const std::string pid = numbers.substr(0, dash), suffix = numbers.substr(dash + 1);
    if (!AllDigits(pid) || !AllDigits(suffix)) return 0;
    return std::stol(pid);
  }
  return 0;
}

std::string NameOutputsNotTemporaries(const std::string& message) {
  // TemporarySibling's names, at the start of a path component, with a component after them.
  static const std::regex kInsideTemporary(R"((^|[/'" ])\.([^/'"]+)\.(partial|old|tmp)-[0-9]+-[0-9]+(?=/))");
  return std::regex_replace(message, kInsideTemporary, "$1$2");
}

bool ProcessRuns(long pid) {
  if (pid <= 0 || pid > 0x7fffffffL) return true;  // not a pid we can ask about: leave it alone
  return kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH;
}

}  // namespace vmap
