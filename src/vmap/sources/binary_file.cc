#include "vmap/sources/binary_file.h"

#include "vmap/core/error.h"
#include "vmap/sources/recording_limits.h"

namespace vmap {
namespace {

[[noreturn]] void CannotOpen(const std::string& path, const std::string& why_not) {
  throw InputError("recording '" + path + "' " + why_not +
                   "; give a recording file (a FIFO, a device or a folder is not one), one you may read");
}

}  // namespace

BinaryFile::BinaryFile(const std::string& path) : path_(path), file_(Opened(ContainedFile::OpenRegular, path)) {}

BinaryFile::BinaryFile(const std::filesystem::path& folder, const std::string& name)
    : path_((folder / name).string()), file_(OpenedInside(folder, name)) {}

ContainedFile BinaryFile::Opened(std::optional<ContainedFile> (*open)(const std::filesystem::path&, std::string*),
                                 const std::string& path) {
  std::string why_not;
  std::optional<ContainedFile> file = open(path, &why_not);
  if (!file) CannotOpen(path, why_not);
  return std::move(*file);
}

ContainedFile BinaryFile::OpenedInside(const std::filesystem::path& folder, const std::string& name) {
  std::string why_not;
  std::optional<ContainedFile> file = ContainedFile::Open(folder, name, &why_not);
  if (!file) CannotOpen((folder / name).string(), why_not);
  return std::move(*file);
}

void BinaryFile::Damaged(uint64_t offset, const std::string& problem) const {
  throw InputError("recording '" + path_ + "' is truncated or damaged at byte " + std::to_string(offset) + ": " +
                   problem);
}

void BinaryFile::OverLimit(uint64_t offset, const std::string& problem) const {
  throw RecordingLimitExceeded("recording '" + path_ + "' is damaged or crafted at byte " + std::to_string(offset) +
                               ": " + problem);
}

void BinaryFile::Read(uint64_t offset, uint64_t count, uint8_t* out, const char* what) {
  if (offset > size() || count > size() - offset) {
    Damaged(offset, std::string(what) + " needs " + std::to_string(count) + " bytes but the file ends at " +
                        std::to_string(size()));
  }
  if (count == 0) return;
  if (!file_.Read(offset, out, count)) Damaged(offset, std::string("cannot read ") + what);
}

void BinaryFile::Read(uint64_t offset, uint64_t count, std::vector<uint8_t>* out, const char* what) {
  if (offset > size() || count > size() - offset) Read(offset, count, static_cast<uint8_t*>(nullptr), what);  // throws
  out->resize(count);
  Read(offset, count, out->data(), what);
}

}  // namespace vmap
