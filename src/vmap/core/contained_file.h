#pragma once
// Reading files that vmap did not necessarily write (a map someone sent, a folder from the internet) without
// being led outside the folder they belong to, into a device, or into reading more than was asked for.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace vmap {

// Whether `inner` is `outer` or lies inside it, comparing the directories they resolve to (symbolic links,
// "..", bind mounts). A path that does not exist yet is compared through its existing ancestors.
bool IsSameOrInside(const std::filesystem::path& inner, const std::filesystem::path& outer);

// Whether `path` is relative and free of "..": it names something inside whatever folder it is relative to,
// as long as no symbolic link leads out (ContainedFile checks that too).
bool IsPlainRelativePath(const std::string& path);

// A regular file inside a folder, open for reading byte ranges (pread): the file is never read whole unless
// asked, so a sparse or huge file costs only what is read.
class ContainedFile {
 public:
  // Opens `directory`/`relative` when it is a regular file that resolves inside `directory`. Otherwise returns
  // nullopt and sets `*why_not` to "is missing", "resolves outside ..." (a symbolic link leading out), or "is
  // not a regular file" (a device, a FIFO, a folder), for the caller to name in its message. `relative` must
  // be a plain relative path (IsPlainRelativePath).
  static std::optional<ContainedFile> Open(const std::filesystem::path& directory, const std::string& relative,
                                           std::string* why_not);
  // A file the user named (a ground truth, a run's JSON, weights, a query image), wherever it is: opened
  // without blocking (a FIFO with no writer) and refused unless it is a regular file, so that neither a device
  // nor a FIFO is ever read. nullopt with `*why_not` as for Open.
  static std::optional<ContainedFile> OpenRegular(const std::filesystem::path& path, std::string* why_not);
  ContainedFile(ContainedFile&& other) noexcept;
  ContainedFile& operator=(ContainedFile&&) = delete;
  ContainedFile(const ContainedFile&) = delete;
  ~ContainedFile();

  const std::filesystem::path& path() const { return path_; }
  std::uint64_t size() const { return size_; }

  // Reads `bytes` bytes at `offset` into `data`; false when the file is shorter (it changed since Open) or
  // cannot be read.
  bool Read(std::uint64_t offset, void* data, std::size_t bytes) const;
  // The whole file; false when it cannot be read.
  bool ReadAll(std::string* bytes) const;
  // Parses the file as JSON without holding its text: at most `max_values` values (every number, string,
  // array and object counts one), nested at most 64 deep. Returns "" or why not ("has more than ... values").
  std::string ParseJson(std::uint64_t max_values, nlohmann::json* document) const;

 private:
  ContainedFile(std::filesystem::path path, int fd, std::uint64_t size)
      : path_(std::move(path)), fd_(fd), size_(size) {}

  std::filesystem::path path_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
};

// The whole of a file the user named (ContainedFile::OpenRegular) of at most `max_bytes`; throws InputError
// "<what> '<path>' <why>; <fix>" otherwise: ReadNamedFile(gt, 256 << 20, "ground truth", "give a poses file").
std::string ReadNamedFile(const std::filesystem::path& path, std::uint64_t max_bytes, const std::string& what,
                          const std::string& fix);

// A JSON file inside `directory` (a ContainedFile) of at most `max_bytes` and `max_values` values (so that its
// parsed form stays within about 32 bytes a value), nested at most 64 deep, parsed.
// On failure `document` is empty and `why_not` says why, naming the file: "map.json is missing", "map.json is
// not valid JSON (...)".
struct ContainedJson {
  std::optional<nlohmann::json> document;
  std::string why_not;
  bool missing = false;  // the file does not exist
};
ContainedJson ReadContainedJson(const std::filesystem::path& directory, const std::string& name,
                                std::uint64_t max_bytes, std::uint64_t max_values);

}  // namespace vmap
