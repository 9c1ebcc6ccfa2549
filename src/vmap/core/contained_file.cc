#include "vmap/core/contained_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>

namespace vmap {
namespace fs = std::filesystem;

bool IsSameOrInside(const fs::path& inner, const fs::path& outer) {
  struct stat outer_stat;
  if (stat(outer.c_str(), &outer_stat) != 0) return false;
  std::error_code ec;
  fs::path path = fs::weakly_canonical(fs::absolute(inner, ec), ec);
  if (ec) path = fs::absolute(inner, ec).lexically_normal();
  // Compare directory identities rather than names: a bind mount or a second symbolic link to the same
  // directory still compares equal.
  for (;;) {
    struct stat path_stat;
    if (stat(path.c_str(), &path_stat) == 0 && path_stat.st_dev == outer_stat.st_dev &&
        path_stat.st_ino == outer_stat.st_ino) {
      return true;
    }
    if (!path.has_relative_path()) return false;
    path = path.parent_path();
  }
}

bool IsPlainRelativePath(const std::string& path) {
  if (path.empty()) return false;
  const fs::path p(path);
  if (p.is_absolute() || p.has_root_name() || p.has_root_directory()) return false;
  for (const auto& part : p) {
    if (part == "..") return false;
  }
  return true;
}

std::optional<ContainedFile> ContainedFile::Open(const fs::path& directory, const std::string& relative,
                                                 std::string* why_not) {
  const fs::path path = directory / relative;
  std::error_code ec;
  if (!IsPlainRelativePath(relative)) {
    *why_not = "points outside '" + directory.string() + "'";
    return std::nullopt;
  }
  if (!fs::exists(fs::symlink_status(path, ec))) {
    *why_not = "is missing";
    return std::nullopt;
  }
  const fs::path real = fs::canonical(path, ec);
  if (ec || !IsSameOrInside(real, directory)) {
    *why_not = "resolves outside '" + directory.string() + "' (a symbolic link leads out of it)";
    return std::nullopt;
  }
  // O_NONBLOCK: opening a FIFO must not wait for a writer. O_NOFOLLOW: `real` has no link left to follow, so
  // one swapped in since is refused rather than followed.
  const int fd = open(real.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOFOLLOW);
  struct stat file_stat;
  if (fd < 0 || fstat(fd, &file_stat) != 0 || !S_ISREG(file_stat.st_mode)) {
    const bool missing = fd < 0 && errno == ENOENT;
    if (fd >= 0) close(fd);
    *why_not = missing ? "is missing" : fd < 0 ? "cannot be opened" : "is not a regular file";
    return std::nullopt;
  }
  return ContainedFile(path, fd, static_cast<std::uint64_t>(file_stat.st_size));
}

ContainedFile::ContainedFile(ContainedFile&& other) noexcept
    : path_(std::move(other.path_)), fd_(other.fd_), size_(other.size_) {
  other.fd_ = -1;
}

ContainedFile::~ContainedFile() {
  if (fd_ >= 0) close(fd_);
}

bool ContainedFile::Read(std::uint64_t offset, void* data, std::size_t bytes) const {
  auto* out = static_cast<char*>(data);
  while (bytes > 0) {
    const ssize_t n = pread(fd_, out, bytes, static_cast<off_t>(offset));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    out += n;
    offset += static_cast<std::uint64_t>(n);
    bytes -= static_cast<std::size_t>(n);
  }
  return true;
}

namespace {
struct TooDeep {};
}  // namespace

ContainedJson ReadContainedJson(const fs::path& directory, const std::string& name, std::uint64_t max_bytes) {
  ContainedJson result;
  std::string why_not;
  const std::optional<ContainedFile> file = ContainedFile::Open(directory, name, &why_not);
  if (!file) {
    result.why_not = name + " " + why_not;
    result.missing = why_not == "is missing";
    return result;
  }
  if (file->size() > max_bytes) {
    result.why_not = name + " is larger than " + std::to_string(max_bytes >> 20) + " MB";
    return result;
  }
  std::string text(file->size(), '\0');
  if (!file->Read(0, text.data(), text.size())) {
    result.why_not = name + " cannot be read";
    return result;
  }
  // Parsing is iterative in nlohmann-json, but printing a value (options are printed again) recurses: bound
  // the nesting, far above anything vmap writes.
  constexpr int kMaxDepth = 64;
  const nlohmann::json::parser_callback_t limit_depth = [](int depth, nlohmann::json::parse_event_t,
                                                           nlohmann::json&) {
    if (depth > kMaxDepth) throw TooDeep{};
    return true;
  };
  try {
    result.document = nlohmann::json::parse(text, limit_depth);
  } catch (const TooDeep&) {
    result.why_not = name + " is nested more than " + std::to_string(kMaxDepth) + " levels deep";
  } catch (const nlohmann::json::exception& error) {
    // parse_error, and out_of_range for a number beyond double's range (1e999)
    result.why_not = name + " is not valid JSON (" + error.what() + ")";
  }
  return result;
}

}  // namespace vmap
