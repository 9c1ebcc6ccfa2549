#include "vmap/core/output_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <optional>

#include "vmap/core/atomic_output.h"
#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/core/temporary_name.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

// Whether `a` and `b` name the same existing file (one inode), whatever the path.
bool SameFile(const fs::path& a, const fs::path& b) {
  struct stat sa, sb;
  return stat(a.c_str(), &sa) == 0 && stat(b.c_str(), &sb) == 0 && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

// A file inside the folder `folder` (at any depth, links not followed) that is `file` under another name: a hard
// link. Only asked for an existing output that has several links, so the walk is rare.
std::optional<fs::path> HardLinkInside(const fs::path& file, const fs::path& folder) {
  struct stat target;
  if (stat(file.c_str(), &target) != 0 || target.st_nlink < 2) return std::nullopt;
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) return std::nullopt;
  for (fs::recursive_directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    struct stat entry;
    if (lstat(it->path().c_str(), &entry) == 0 && S_ISREG(entry.st_mode) && entry.st_dev == target.st_dev &&
        entry.st_ino == target.st_ino) {
      return it->path();
    }
  }
  return std::nullopt;
}

// Whether the regular file `path` is a program: an ELF binary or a script ("#!"). Judged by its first bytes, not
// by its execute bits, which every file on a FAT or exFAT stick (where robots often write) carries.
bool IsProgram(const fs::path& path) {
  const int fd = open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return false;
  char head[4] = {};
  const ssize_t read_bytes = read(fd, head, sizeof(head));
  close(fd);
  return (read_bytes >= 2 && head[0] == '#' && head[1] == '!') ||
         (read_bytes == 4 && head[0] == '\x7f' && head[1] == 'E' && head[2] == 'L' && head[3] == 'F');
}

// Why a file cannot be created beside `path` as the output's temporary will be (a name too long, a folder this user
// may not write, a read-only or pseudo file system), found by creating one and removing it at once: so that the
// refusal comes before the work, not after it. "" when it can.
std::string WhyNotCreatable(const fs::path& path) {
  // Named as the output's temporaries are: one left by a kill in between is removed by the next run.
  const fs::path probe = TemporarySibling(path, "tmp");
  const int fd = open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0600);
  if (fd < 0) {
    if (errno == EEXIST) return "";  // a name already taken there: the folder takes files
    if (errno == ENAMETOOLONG && path.filename().native().size() <= 255) return kNameTooLongForTemporary;
    return std::strerror(errno);
  }
  close(fd);
  unlink(probe.c_str());
  return "";
}

}  // namespace

bool SameOutput(const fs::path& a, const fs::path& b) {
  if (SameFile(a, b)) return true;
  std::error_code ec;
  const fs::path ca = fs::weakly_canonical(fs::absolute(a, ec), ec);
  const fs::path cb = fs::weakly_canonical(fs::absolute(b, ec), ec);
  return !ca.empty() && ca == cb;
}

std::string WhyNotReplaceable(const fs::path& path) {
  struct stat status;
  if (lstat(path.c_str(), &status) != 0) return "";  // absent: created
  if (S_ISLNK(status.st_mode)) {
    return "is a symbolic link; vmap replaces only a regular file: give the path it points to, or another path";
  }
  if (S_ISDIR(status.st_mode)) return "is a folder; give a file name";
  if (!S_ISREG(status.st_mode)) {
    return "is not a regular file (a device, a FIFO or a socket), which vmap never replaces; give a file name";
  }
  // Root may write anything: the permission bits still say the file is meant to stay as it is.
  if ((status.st_mode & (S_IWUSR | S_IWGRP | S_IWOTH)) == 0 || access(path.c_str(), W_OK) != 0) {
    return "is read-only; make it writable or give another path";
  }
  // No output of vmap is a program, so one in the way is a slip of the path (--json build/vmap), not an
  // earlier run's output.
  if (IsProgram(path)) return "is a program (an executable or a script), which vmap never replaces; give another path";
  return "";
}

void CheckOutputFiles(const std::vector<OutputFile>& outputs, const std::vector<OutputInput>& inputs) {
  for (size_t i = 0; i < outputs.size(); ++i) {
    const OutputFile& output = outputs[i];
    if (output.path.empty()) continue;
    // An OptionError of the output's field (a front end names it, e.g. by its flag), the path quoted.
    const std::string path = "'" + output.path.string() + "'";
    for (const OutputInput& input : inputs) {
      if (input.path.empty()) continue;
      // The same file (also where neither exists yet: a cache this run may write), or a path into a folder.
      if (SameOutput(output.path, input.path)) {
        throw OptionError(output.flag, path + " would overwrite " + input.what + " '" + input.path.string() +
                                           "', an input of this command; write it somewhere else");
      }
      if (IsSameOrInside(output.path, input.path)) {
        throw OptionError(output.flag, path + " lies inside " + input.what + " '" + input.path.string() +
                                           "', an input of this command; write it somewhere else");
      }
      if (const std::optional<fs::path> link = HardLinkInside(output.path, input.path)) {
        throw OptionError(output.flag, path + " is a hard link of '" + link->string() + "' in " + input.what + " '" +
                                           input.path.string() +
                                           "', an input of this command; write it somewhere else");
      }
    }
    for (size_t j = 0; j < i; ++j) {
      if (!outputs[j].path.empty() && SameOutput(output.path, outputs[j].path)) {
        throw OptionError(output.flag,
                          path + " is also the output of " + outputs[j].flag + "; give each output its own file",
                          {outputs[j].flag});
      }
    }
    const std::string why_not = WhyNotReplaceable(output.path);
    if (!why_not.empty()) throw OptionError(output.flag, path + " " + why_not);
    const fs::path parent = output.path.has_parent_path() ? output.path.parent_path() : fs::path(".");
    std::error_code ec;
    if (!fs::is_directory(parent, ec)) {
      throw OptionError(output.flag, path + ": its folder '" + parent.string() + "' does not exist; create it first");
    }
    if (const std::string problem = WhyNotCreatable(output.path); !problem.empty()) {
      throw OptionError(output.flag, path + " cannot be written: " + problem +
                                         (problem == kNameTooLongForTemporary
                                              ? ""
                                              : "; give a path in a folder where this user may create files"));
    }
  }
}

}  // namespace vmap
