#include "vmap/core/contained_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

#include "vmap/core/error.h"

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
    const int error = errno;
    if (fd >= 0) close(fd);
    *why_not = fd < 0 && error == ENOENT ? "is missing"
               : fd < 0                  ? "cannot be opened (" + std::string(std::strerror(error)) + ")"
                                         : "is not a regular file";
    return std::nullopt;
  }
  return ContainedFile(path, fd, static_cast<std::uint64_t>(file_stat.st_size));
}

std::optional<ContainedFile> ContainedFile::OpenRegular(const fs::path& path, std::string* why_not) {
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  struct stat file_stat;
  if (fd < 0 || fstat(fd, &file_stat) != 0 || !S_ISREG(file_stat.st_mode)) {
    const int error = errno;
    if (fd >= 0) close(fd);
    *why_not = fd < 0 && error == ENOENT ? "is missing"
               : fd < 0                  ? "cannot be opened (" + std::string(std::strerror(error)) + ")"
                                         : "is not a regular file (a device, a FIFO or a folder)";
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

bool ContainedFile::ReadAll(std::string* bytes) const {
  bytes->assign(size_, '\0');
  return Read(0, bytes->data(), bytes->size());
}

namespace {

// Builds the document as nlohmann-json's own DOM parser does (json::parse without a callback), counting values
// and nesting on the way. Not json::parse with a callback: after every object that parser searches the
// object's parent for a discarded member (json_sax_dom_callback_parser::end_object in nlohmann-json 3.11), so an
// array of n objects costs n^2 / 2 steps: a map.json of 400,000 small objects took `vmap info` 41 s.
class BoundedDomBuilder {
 public:
  using json = nlohmann::json;
  BoundedDomBuilder(json* document, std::uint64_t max_values, int max_depth)
      : dom_(*document, /*allow_exceptions=*/true), max_values_(max_values), max_depth_(max_depth) {}

  bool too_deep() const { return too_deep_; }
  bool too_many() const { return too_many_; }

  bool null() { return Count() && dom_.null(); }
  bool boolean(bool value) { return Count() && dom_.boolean(value); }
  bool number_integer(json::number_integer_t value) { return Count() && dom_.number_integer(value); }
  bool number_unsigned(json::number_unsigned_t value) { return Count() && dom_.number_unsigned(value); }
  bool number_float(json::number_float_t value, const json::string_t& text) {
    return Count() && dom_.number_float(value, text);
  }
  bool string(json::string_t& value) { return Count() && dom_.string(value); }
  bool binary(json::binary_t& value) { return Count() && dom_.binary(value); }
  bool start_object(std::size_t size) { return Count() && Enter() && dom_.start_object(size); }
  bool key(json::string_t& value) { return dom_.key(value); }
  bool end_object() { return Leave() && dom_.end_object(); }
  bool start_array(std::size_t size) { return Count() && Enter() && dom_.start_array(size); }
  bool end_array() { return Leave() && dom_.end_array(); }
  template <class Exception>
  bool parse_error(std::size_t position, const std::string& last_token, const Exception& error) {
    return dom_.parse_error(position, last_token, error);  // throws it
  }

 private:
  // A container counts twice (its start and its end), as the parser's callback events did before.
  bool Count() {
    if (++values_ > max_values_) too_many_ = true;
    return !too_many_;
  }
  bool Enter() {
    if (++depth_ > max_depth_) too_deep_ = true;
    return !too_deep_;
  }
  bool Leave() {
    --depth_;
    return Count();
  }

  nlohmann::detail::json_sax_dom_parser<json> dom_;
  std::uint64_t max_values_;
  int max_depth_;
  std::uint64_t values_ = 0;
  int depth_ = 0;
  bool too_deep_ = false;
  bool too_many_ = false;
};

}  // namespace

std::string ContainedFile::ParseJson(std::uint64_t max_values, nlohmann::json* document) const {
  // A stream of its own over the file: the text is never held whole, only the parsed values.
  const int copy = dup(fd_);
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> stream(copy >= 0 ? fdopen(copy, "rb") : nullptr, &std::fclose);
  if (!stream) {
    if (copy >= 0) close(copy);
    return "cannot be read";
  }
  // Parsing is iterative in nlohmann-json, but printing a value (options are printed again) recurses: bound
  // the nesting, far above anything vmap writes.
  constexpr int kMaxDepth = 64;
  nlohmann::json parsed;
  BoundedDomBuilder builder(&parsed, max_values, kMaxDepth);
  try {
    const bool complete = nlohmann::json::sax_parse(stream.get(), &builder);
    if (builder.too_deep()) return "is nested more than " + std::to_string(kMaxDepth) + " levels deep";
    if (builder.too_many()) {
      return "holds more than " + std::to_string(max_values) + " values, more than vmap ever writes there";
    }
    if (!complete) return "is not valid JSON (damaged or not a file vmap wrote)";
  } catch (const nlohmann::json::parse_error& error) {
    return "is not valid JSON (at byte " + std::to_string(error.byte) + "; damaged or not a file vmap wrote)";
  } catch (const nlohmann::json::out_of_range&) {
    return "holds a number too large for a double (1e999: damaged or not a file vmap wrote)";
  } catch (const nlohmann::json::exception&) {
    return "is not valid JSON (damaged or not a file vmap wrote)";
  }
  *document = std::move(parsed);
  return "";
}

std::string ReadNamedFile(const fs::path& path, std::uint64_t max_bytes, const std::string& what,
                          const std::string& fix) {
  std::string why_not;
  const std::optional<ContainedFile> file = ContainedFile::OpenRegular(path, &why_not);
  const std::string named = what + " '" + path.string() + "' ";
  if (!file) throw InputError(named + why_not + "; " + fix);
  if (file->size() > max_bytes) {
    throw InputError(named + "is larger than " + std::to_string(max_bytes >> 20) + " MB, more than any " + what +
                     " vmap reads; " + fix);
  }
  std::string bytes;
  if (!file->ReadAll(&bytes)) throw InputError(named + "cannot be read; " + fix);
  return bytes;
}

ContainedJson ReadContainedJson(const fs::path& directory, const std::string& name, std::uint64_t max_bytes,
                                std::uint64_t max_values) {
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
  nlohmann::json document;
  why_not = file->ParseJson(max_values, &document);
  if (why_not.empty()) {
    result.document = std::move(document);
  } else {
    result.why_not = name + " " + why_not;
  }
  return result;
}

}  // namespace vmap
