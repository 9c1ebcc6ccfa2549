#include "vmap/core/image_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include <opencv2/imgcodecs.hpp>

#include "vmap/core/error.h"

namespace vmap {
namespace {

// What to do about a failed write, by its errno.
std::string Hint(int error) {
  if (error == ENOSPC || error == EDQUOT) return "free some space on its file system";
  if (error == EACCES || error == EPERM || error == EROFS) return "check that its folder is writable";
  return "check its folder and the free space";
}

}  // namespace

void WriteImageFile(const std::filesystem::path& path, const cv::Mat& image, const std::string& what,
                    const std::vector<int>& params) {
  const std::string name = what + " '" + path.string() + "'";
  std::vector<unsigned char> bytes;
  bool encoded = false;
  try {
    encoded = !image.empty() && cv::imencode(path.extension().string(), image, bytes, params);
  } catch (const cv::Exception& e) {
    throw InputError("cannot encode " + name + " (" + LibraryMessage(e) + ")");
  }
  if (!encoded) throw InputError("cannot encode " + name + " as " + path.extension().string());
  WriteImageBytes(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), what);
}

void WriteImageBytes(const std::filesystem::path& path, std::string_view bytes, const std::string& what) {
  const std::string name = what + " '" + path.string() + "'";
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK, 0666);
  if (fd < 0) {
    const int error = errno;
    throw InputError("cannot write " + name + " (" + std::strerror(error) + "); " + Hint(error));
  }
  // Only a regular file is written, and so removed on failure: never a device or a FIFO (not waited on either).
  struct stat status {};
  if (::fstat(fd, &status) != 0 || !S_ISREG(status.st_mode)) {
    ::close(fd);
    throw InputError("cannot write " + name + ": it is not a regular file");
  }
  int error = 0;
  for (size_t written = 0; written < bytes.size() && error == 0;) {
    const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      error = n < 0 ? errno : ENOSPC;  // a write of nothing to a regular file: no room left
    } else {
      written += static_cast<size_t>(n);
    }
  }
  if (::close(fd) != 0 && error == 0) error = errno;
  if (error != 0) {
    ::unlink(path.c_str());
    throw InputError("cannot write " + name + " (" + std::strerror(error) + "); " + Hint(error));
  }
}

void CopyImageFile(const std::filesystem::path& source, const std::filesystem::path& path, const std::string& what) {
  std::ifstream in(source, std::ios::binary);
  std::ostringstream bytes;
  if (!(in && bytes << in.rdbuf())) {
    throw InputError("cannot read '" + source.string() + "' to keep it as " + what + " '" + path.string() + "'");
  }
  WriteImageBytes(path, bytes.str(), what);
}

}  // namespace vmap
