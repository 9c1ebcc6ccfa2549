#include "vmap/core/atomic_output.h"

#include <unistd.h>

#include <fstream>
#include <random>

#include "vmap/core/error.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

// A unique sibling name; the pid and a random suffix keep concurrent runs apart.
fs::path TemporarySibling(const fs::path& path, const char* tag) {
  std::random_device rd;
  const fs::path parent = path.has_parent_path() ? path.parent_path() : fs::path(".");
  return parent / ("." + path.filename().string() + "." + tag + "-" + std::to_string(getpid()) + "-" +
                   std::to_string(rd() % 1000000));
}

}  // namespace

void WriteFileAtomically(const fs::path& path, std::string_view content) {
  const fs::path temp = TemporarySibling(path, "tmp");
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) {
      throw InputError("cannot write '" + path.string() +
                       "': the directory does not exist or is not writable; choose another output path");
    }
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
    out.flush();
    if (!out) {
      std::error_code ignored;
      fs::remove(temp, ignored);
      throw InputError("writing '" + path.string() + "' failed (disk full?)");
    }
  }
  fs::rename(temp, path);
}

AtomicOutputDirectory::AtomicOutputDirectory(fs::path final_path, const std::string& ownership_marker)
    : final_path_(std::move(final_path)) {
  if (final_path_.filename().empty()) final_path_ = final_path_.parent_path();  // "out/" -> "out"
  if (fs::exists(final_path_)) {
    if (!fs::is_directory(final_path_)) {
      throw InputError("output '" + final_path_.string() + "' exists and is not a directory; choose another path");
    }
    const bool empty = fs::directory_iterator(final_path_) == fs::directory_iterator();
    if (!empty && !ownership_marker.empty() && !fs::exists(final_path_ / ownership_marker)) {
      throw InputError("output '" + final_path_.string() + "' exists and is not vmap's (it has no " +
                       ownership_marker + "); vmap will not replace it: choose another output directory");
    }
  }
  const fs::path parent = final_path_.has_parent_path() ? final_path_.parent_path() : fs::path(".");
  std::error_code ec;
  fs::create_directories(parent, ec);
  temp_path_ = TemporarySibling(final_path_, "partial");
  if (!fs::create_directory(temp_path_, ec) || ec) {
    throw InputError("cannot create a directory next to '" + final_path_.string() + "' (" + ec.message() +
                     "); check that '" + parent.string() + "' is writable");
  }
}

AtomicOutputDirectory::~AtomicOutputDirectory() {
  if (!committed_) {
    std::error_code ignored;
    fs::remove_all(temp_path_, ignored);
  }
}

void AtomicOutputDirectory::Commit() {
  if (committed_) return;
  // rename() cannot replace a non-empty directory: move the old one aside first, then drop it.
  fs::path old_aside;
  if (fs::exists(final_path_)) {
    old_aside = TemporarySibling(final_path_, "old");
    fs::rename(final_path_, old_aside);
  }
  fs::rename(temp_path_, final_path_);
  committed_ = true;
  if (!old_aside.empty()) {
    std::error_code ignored;
    fs::remove_all(old_aside, ignored);
  }
}

}  // namespace vmap
