#include "vmap/sources/binary_file.h"

#include <sys/types.h>

#include "vmap/core/error.h"

namespace vmap {

BinaryFile::BinaryFile(const std::string& path) : path_(path), file_(std::fopen(path.c_str(), "rb")) {
  if (!file_) throw InputError("cannot open '" + path + "'; check that it exists and that you may read it");
  if (fseeko(file_.get(), 0, SEEK_END) != 0) throw InputError("cannot read '" + path + "'; it is not a regular file");
  size_ = static_cast<uint64_t>(ftello(file_.get()));
}

void BinaryFile::Damaged(uint64_t offset, const std::string& problem) const {
  throw InputError("recording '" + path_ + "' is truncated or damaged at byte " + std::to_string(offset) + ": " +
                   problem);
}

void BinaryFile::Read(uint64_t offset, uint64_t count, uint8_t* out, const char* what) {
  if (offset > size_ || count > size_ - offset) {
    Damaged(offset, std::string(what) + " needs " + std::to_string(count) + " bytes but the file ends at " +
                        std::to_string(size_));
  }
  if (count == 0) return;
  if (fseeko(file_.get(), static_cast<off_t>(offset), SEEK_SET) != 0 ||
      std::fread(out, 1, count, file_.get()) != count) {
    Damaged(offset, std::string("cannot read ") + what);
  }
}

void BinaryFile::Read(uint64_t offset, uint64_t count, std::vector<uint8_t>* out, const char* what) {
  if (offset > size_ || count > size_ - offset) Read(offset, count, static_cast<uint8_t*>(nullptr), what);  // throws
  out->resize(count);
  Read(offset, count, out->data(), what);
}

}  // namespace vmap
