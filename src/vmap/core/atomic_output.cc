#include "vmap/core/atomic_output.h"

#include <fcntl.h>
#include <signal.h>
#include <stdio.h>  // renameat2, RENAME_EXCHANGE (glibc >= 2.28)
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <functional>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "vmap/core/contained_file.h"
#include "vmap/core/directory_lock.h"
#include "vmap/core/error.h"
#include "vmap/core/file_sync.h"
#include "vmap/core/output_file.h"
#include "vmap/core/temporary_name.h"
#include "vmap/core/temporary_registry.h"

namespace vmap {
namespace fs = std::filesystem;
using internal::CreateRegistered;
using internal::RemoveAndUnregister;
using internal::Temporaries;

namespace {

std::string ErrnoText() { return std::strerror(errno); }

[[noreturn]] void Refuse(const fs::path& path, const std::string& why_and_fix) {
  throw InputError("output '" + path.string() + "' " + why_and_fix);
}

// A visible sibling name of `final_path` that no later run takes for a dead process's temporary
// (RemoveStaleTemporaries), and that nothing holds yet: "NAME.TAG-TIME".
fs::path VisibleSibling(const fs::path& final_path, const std::string& tag) {
  const std::string stamp = std::to_string(
      std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch()).count());
  fs::path visible = final_path;
  visible += "." + tag + "-" + stamp;
  std::error_code exists;
  for (int n = 2; fs::exists(fs::symlink_status(visible, exists)); ++n) {
    visible = final_path;
    visible += "." + tag + "-" + stamp + "-" + std::to_string(n);
  }
  return visible;
}

// Moves the entries of `from` that are not the output's own, and that `to` holds none of, into `to`. Returns the
// names moved; those that could not be are added to `failed`.
std::vector<std::string> CarryOver(const fs::path& from, const fs::path& to,
                                   const std::function<bool(const std::string&)>& is_own,
                                   std::vector<std::string>* failed) {
  std::vector<std::string> names, carried;
  std::error_code ec;
  for (fs::directory_iterator it(from, ec), end; !ec && it != end; it.increment(ec)) {
    names.push_back(it->path().filename().string());
  }
  if (ec) failed->push_back("its list of files (" + ec.message() + ")");
  for (const std::string& name : names) {
    std::error_code exists;
    if (is_own(name) || fs::exists(fs::symlink_status(to / name, exists))) continue;
    (rename((from / name).c_str(), (to / name).c_str()) == 0 ? &carried : failed)->push_back(name);
  }
  return carried;
}

}  // namespace

void WriteFileAtomically(const fs::path& path, std::string_view content,
                         const std::vector<TemporaryDirectory*>& completes) {
  PendingFile(path, content).Commit(completes);
}

PendingFile::PendingFile(fs::path destination, std::string_view content) : path_(std::move(destination)) {
  const fs::path& path = path_;
  // Refused before anything is written, and again before the rename (the path may have changed meanwhile).
  if (const std::string why_not = WhyNotReplaceable(path); !why_not.empty()) Refuse(path, why_not);
  RemoveStaleTemporaries(path);
  fs::path temp;
  int fd = -1;
  for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
    temp = TemporarySibling(path, "tmp");
    fd = CreateRegistered(temp,
                          [&] {
                            const int opened = open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
                            return opened >= 0 ? opened + 1 : 0;  // 0: not created
                          }) -
         1;
    if (fd < 0 && errno != EEXIST) break;
  }
  if (fd < 0) {
    if (errno == ENAMETOOLONG && path.filename().native().size() <= 255)
      throw InputError("cannot write '" + path.string() + "': " + kNameTooLongForTemporary);
    throw InputError("cannot write '" + path.string() + "' (" + ErrnoText() +
                     "); check that its directory exists and is writable, or choose another output path");
  }
  const auto fail = [&](const std::string& what) {
    const std::string reason = ErrnoText();
    close(fd);
    RemoveAndUnregister(temp);
    throw InputError(what + " '" + path.string() + "' failed (" + reason +
                     "); check the free space and the "
                     "permissions of its directory");
  };
  // A file replaced keeps its permissions (a private 0600 --json stays private), as an editor's save keeps them.
  if (struct stat existing{}; stat(path.c_str(), &existing) == 0 && S_ISREG(existing.st_mode)) {
    fchmod(fd, existing.st_mode & 07777);
  }
  for (size_t written = 0; written < content.size();) {
    const ssize_t n = write(fd, content.data() + written, content.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail("writing");
    written += static_cast<size_t>(n);
  }
  // A file inside a temporary folder is synced with the folder, when the folder is committed.
  {
    std::lock_guard<std::mutex> lock(Temporaries().mutex);
    inside_temporary_ = Temporaries().paths.count(path.parent_path()) > 0;
  }
  if (!inside_temporary_ && fsync(fd) != 0 && errno != EINVAL && errno != EROFS) fail("writing");
  if (close(fd) != 0) {
    fd = -1;
    const std::string reason = ErrnoText();
    RemoveAndUnregister(temp);
    throw InputError("writing '" + path.string() + "' failed (" + reason + "); check the free space");
  }
  temp_ = temp;
}

PendingFile::~PendingFile() {
  if (!temp_.empty()) RemoveAndUnregister(temp_);
}

void PendingFile::Commit(const std::vector<TemporaryDirectory*>& completes) {
  if (temp_.empty()) throw std::logic_error("PendingFile::Commit called twice for '" + path_.string() + "'");
  const fs::path& path = path_;
  const fs::path temp = std::exchange(temp_, fs::path());  // removed below on failure, never by the destructor
  if (const std::string why_not = WhyNotReplaceable(path); !why_not.empty()) {
    RemoveAndUnregister(temp);
    Refuse(path, why_not);
  }
  if (!completes.empty()) SyncFileSystemOf(path.parent_path());  // the folders this file makes part of the output
  std::unique_lock<std::mutex> lock(Temporaries().mutex);
  if (rename(temp.c_str(), path.c_str()) != 0) {
    const std::string reason = ErrnoText();
    lock.unlock();
    RemoveAndUnregister(temp);
    throw InputError("cannot replace '" + path.string() + "' (" + reason +
                     "); check that it is not a folder and "
                     "that its directory is writable");
  }
  Temporaries().Remove(temp);
  for (TemporaryDirectory* directory : completes) {
    Temporaries().Remove(directory->path_);
    directory->completed_ = true;
  }
  lock.unlock();
  if (!inside_temporary_) SyncDirectory(path.parent_path());
}

TemporaryDirectory::TemporaryDirectory(const fs::path& near) {
  RemoveStaleTemporaries(near);
  for (int attempt = 0; attempt < 100 && path_.empty(); ++attempt) {
    const fs::path candidate = TemporarySibling(near, "partial");
    if (CreateRegistered(candidate, [&] { return mkdir(candidate.c_str(), 0777) == 0; })) {
      path_ = candidate;
    } else if (errno != EEXIST) {
      break;
    }
  }
  if (path_.empty()) {
    throw InputError("cannot create a folder next to '" + near.string() + "' (" + ErrnoText() +
                     "); check that its folder exists and is writable");
  }
}

TemporaryDirectory::~TemporaryDirectory() {
  if (!completed_) RemoveAndUnregister(path_);
}

void TemporaryDirectory::MoveTo(const fs::path& from, const fs::path& to) {
  const auto fail = [&](const std::string& why) {
    throw InputError("cannot move '" + from.string() + "' to '" + to.string() + "' (" + why +
                     "); check the permissions of '" + to.parent_path().string() + "'");
  };
  // The parent opened without following a link: a symbolic link put in its place is refused, not followed.
  const int parent = open(to.parent_path().c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (parent < 0) {
    fail(errno == ELOOP || errno == ENOTDIR ? "it is a symbolic link or not a folder; vmap writes nothing through "
                                              "a link"
                                            : ErrnoText());
  }
  const std::string name = to.filename().string();
  std::lock_guard<std::mutex> lock(Temporaries().mutex);  // an interruption sees it before or after, never lost
  int moved = renameat2(AT_FDCWD, from.c_str(), parent, name.c_str(), RENAME_NOREPLACE);
  if (moved != 0 && (errno == EINVAL || errno == ENOSYS || errno == ENOTSUP)) {
    // No RENAME_NOREPLACE on this file system: rename() would replace an empty folder, so look first.
    struct stat existing;
    if (fstatat(parent, name.c_str(), &existing, AT_SYMLINK_NOFOLLOW) == 0) {
      errno = EEXIST;
    } else {
      moved = renameat(AT_FDCWD, from.c_str(), parent, name.c_str());
    }
  }
  const int error = errno;
  close(parent);
  if (moved != 0) {
    errno = error;
    fail(error == EEXIST || error == ENOTEMPTY ? "it exists already" : ErrnoText());
  }
  // What a failure must remove from now on: `to` (moved out of the folder, the rest of the folder stays ours).
  if (from != path_) {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  Temporaries().Remove(path_);
  path_ = to;
  Temporaries().Add(path_);
}

OutputPolicy OutputPolicy::InsideVmapOutput() {
  OutputPolicy policy;
  policy.why_not_ours = [](const fs::path&) { return std::string(); };
  return policy;
}

namespace {

// "out/", "." and ".." name the directory itself.
fs::path DirectoryName(fs::path path) {
  const fs::path name = path.filename();
  if (name.empty() || name == "." || name == "..") {
    std::error_code ec;
    path = fs::absolute(path, ec).lexically_normal();
    if (path.filename().empty()) path = path.parent_path();
  }
  if (path.filename().empty() || !path.has_relative_path()) {
    Refuse(path, "is the root of the file system; choose a directory to write into");
  }
  return path;
}

}  // namespace

void CheckOutputDirectory(const fs::path& final_path, const OutputPolicy& policy) {
  // The check of a directory about to be written, and nothing else: the object is never constructed.
  AtomicOutputDirectory::CheckReplaceable(DirectoryName(final_path), policy);
}

AtomicOutputDirectory::AtomicOutputDirectory(fs::path final_path, OutputPolicy policy)
    : final_path_(DirectoryName(std::move(final_path))), policy_(std::move(policy)) {
  CheckReplaceable();
  const fs::path parent = final_path_.has_parent_path() ? final_path_.parent_path() : fs::path(".");
  RemoveStaleTemporaries(final_path_);
  std::error_code missing;
  for (fs::path folder = parent; !folder.empty() && !fs::exists(fs::symlink_status(folder, missing));
       folder = folder.parent_path()) {
    // "ghost/.." names no folder of its own: create_directories makes "ghost", the one to remove on failure.
    if (folder.filename() != ".." && folder.filename() != ".") created_parents_.push_back(folder);
  }
  for (int attempt = 0; attempt < 100 && temp_path_.empty(); ++attempt) {
    const fs::path candidate = TemporarySibling(final_path_, "partial");
    // The parent is created under the registry's lock too: when it lies in another temporary output (a
    // sweep's map), an interruption that removed that one must not see it recreated.
    const auto create = [&] {
      std::error_code ec;
      fs::create_directories(parent, ec);
      return mkdir(candidate.c_str(), 0777) == 0;
    };
    if (CreateRegistered(candidate, create)) {
      temp_path_ = candidate;
    } else if (errno == ENAMETOOLONG && final_path_.filename().native().size() <= 255) {
      throw InputError("cannot create '" + final_path_.string() + "': " + kNameTooLongForTemporary);
    } else if (errno != EEXIST) {
      throw InputError("cannot create a directory next to '" + final_path_.string() + "' (" + ErrnoText() +
                       "); check that '" + parent.string() + "' exists and is writable");
    }
  }
  if (temp_path_.empty())
    throw InputError("cannot create a temporary directory next to '" + final_path_.string() + "'");
}

AtomicOutputDirectory::~AtomicOutputDirectory() {
  if (committed_) return;
  if (!temp_path_.empty()) RemoveAndUnregister(temp_path_);
  // rmdir, not remove_all: a folder something else wrote into since is no longer only this output's.
  for (const fs::path& folder : created_parents_) {
    if (rmdir(folder.c_str()) != 0) break;
  }
}

void AtomicOutputDirectory::CheckReplaceable() const { CheckReplaceable(final_path_, policy_); }

void AtomicOutputDirectory::CheckReplaceable(const fs::path& final_path, const OutputPolicy& policy) {
  // The input first: replacing it would be the worst loss, whatever else the folder is.
  for (const fs::path& input : policy.inputs) {
    if (IsSameOrInside(input, final_path)) {
      Refuse(final_path, "is or holds the input '" + input.string() +
                             "', which replacing it would delete; write the output somewhere else");
    }
    if (IsSameOrInside(final_path, input)) {
      Refuse(final_path,
             "lies inside the input '" + input.string() + "'; write the output somewhere else than into the input");
    }
  }
  // Replaced, it would leave the shell that ran vmap in a removed folder, where `ls` shows nothing.
  std::error_code here_ec;
  const fs::path here = fs::current_path(here_ec);
  if (!here_ec && IsSameOrInside(here, final_path)) {
    Refuse(final_path, "is or holds the folder vmap runs in ('" + here.string() +
                           "'), which replacing it would remove from under you; give another path, e.g. a new folder");
  }
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(final_path, ec);
  if (ec && status.type() != fs::file_type::not_found) {
    Refuse(final_path, "cannot be inspected (" + ec.message() + "); check its permissions or choose another path");
  }
  if (fs::exists(status)) {
    if (fs::is_symlink(status)) {
      Refuse(final_path,
             "is a symbolic link; vmap replaces only a real directory: give the path it points to, "
             "or choose another output path");
    }
    if (!fs::is_directory(status)) Refuse(final_path, "exists and is not a directory; choose another path");
    fs::directory_iterator entries(final_path, ec);
    if (ec) Refuse(final_path, "cannot be read (" + ec.message() + "); check its permissions");
    if (entries != fs::directory_iterator()) {
      const std::string why_not = policy.why_not_ours
                                      ? RethrowAsInputError(
                                            [&] {
                                              return ErrorContext{"cannot inspect output '" + final_path.string() + "'",
                                                                  "check its permissions"};
                                            },
                                            [&] { return policy.why_not_ours(final_path); })
                                      : std::string("it is not empty");
      if (!why_not.empty()) {
        Refuse(final_path, "exists and is not " + policy.kind + " (" + why_not +
                               "), so vmap will not replace it: vmap replaces only an empty folder or " + policy.kind +
                               " it wrote. Choose another output directory, or move the folder away "
                               "yourself");
      }
    }
  }
}

void AtomicOutputDirectory::Commit() {
  if (committed_) return;
  if (temp_path_.empty()) throw std::logic_error("AtomicOutputDirectory::Commit after its directory was kept");
  try {
    MoveIntoPlace();
  } catch (const InputError& error) {
    if (!policy_.keep_if_commit_fails) throw;
    throw InputError(std::string(error.what()) + "; " + KeepUnplaced());
  }
}

std::string AtomicOutputDirectory::KeepUnplaced() {
  // A visible name that no later run takes for a dead process's temporary (RemoveStaleTemporaries); where even
  // that rename fails (the folder became unwritable), the temporary stays as it is, no longer this process's to
  // remove.
  fs::path kept = VisibleSibling(final_path_, "unplaced");
  std::lock_guard<std::mutex> lock(Temporaries().mutex);
  if (rename(temp_path_.c_str(), kept.c_str()) != 0) kept = temp_path_;
  Temporaries().Remove(temp_path_);
  temp_path_.clear();  // the destructor leaves it
  return "the finished output is kept at '" + kept.string() + "': move it into place yourself";
}

void AtomicOutputDirectory::MoveIntoPlace() {
  // Another vmap writing into the folder being replaced (`build --add-experience-to` a map) finishes first:
  // replacing it now would throw its work away while it still thinks it is writing it.
  // Not a temporary of this process's own (`vmap simulate` builds its map into one): no other process writes into
  // it, and the lock this process holds on it (HoldLock) would have this one wait for itself.
  std::optional<DirectoryWriteLock> writers;
  std::error_code exists_ec;
  bool ours = false;
  {
    std::lock_guard<std::mutex> lock(Temporaries().mutex);
    ours = Temporaries().paths.count(final_path_) > 0;
  }
  if (!ours && fs::is_directory(fs::symlink_status(final_path_, exists_ec))) writers.emplace(final_path_, "the output");
  SyncFileSystemOf(temp_path_);  // what the folder holds is on disk before a rename names it
  CheckReplaceable();            // the folder may have changed while vmap worked
  fs::path old;                  // where the replaced directory ends up, to be removed
  std::unique_lock<std::mutex> lock(Temporaries().mutex);
  std::error_code ec;
  const bool replacing = fs::exists(fs::symlink_status(final_path_, ec));
  auto fail = [&](const std::string& reason) {
    throw InputError("cannot move the finished output into place at '" + final_path_.string() + "' (" + reason +
                     "); check that its directory is writable");
  };
  if (!replacing) {
    if (rename(temp_path_.c_str(), final_path_.c_str()) != 0) fail(ErrnoText());
    Temporaries().Remove(temp_path_);
  } else if (renameat2(AT_FDCWD, temp_path_.c_str(), AT_FDCWD, final_path_.c_str(), RENAME_EXCHANGE) == 0) {
    old = temp_path_;  // still registered: it now holds the replaced directory
  } else if (errno == EINVAL || errno == ENOSYS || errno == ENOTSUP) {
    // No atomic exchange on this file system: move the old directory aside first. An interruption between
    // the two renames is excluded by the registry's lock; only SIGKILL could leave the old copy aside.
    old = TemporarySibling(final_path_, "old");
    if (rename(final_path_.c_str(), old.c_str()) != 0) fail(ErrnoText());
    Temporaries().Add(old);
    if (rename(temp_path_.c_str(), final_path_.c_str()) != 0) {
      const std::string reason = ErrnoText();
      rename(old.c_str(), final_path_.c_str());  // put the old directory back
      Temporaries().Remove(old);
      fail(reason);
    }
    Temporaries().Remove(temp_path_);
  } else {
    fail(ErrnoText());
  }
  // Under the registry's lock: an interruption, which removes the replaced directory, waits until they are moved.
  std::vector<std::string> carried, not_carried;
  if (!old.empty() && policy_.is_own_entry) carried = CarryOver(old, final_path_, policy_.is_own_entry, &not_carried);
  committed_ = true;
  if (!not_carried.empty()) {
    // Not removed with what they are in: the replaced directory stays, under a name the user sees.
    const fs::path kept = VisibleSibling(final_path_, "replaced");
    if (rename(old.c_str(), kept.c_str()) == 0) {
      Temporaries().Remove(old);
      old = kept;
    }
  }
  lock.unlock();
  SyncDirectory(final_path_.parent_path());
  if (!carried.empty()) {
    std::sort(carried.begin(), carried.end());
    spdlog::info("'{}' replaced {} and keeps what it held besides its own files: {}", final_path_.string(),
                 policy_.kind, fmt::format("{}", fmt::join(carried, ", ")));
  }
  if (!not_carried.empty()) {
    spdlog::warn("'{}' replaced {}, but could not keep {} from it; the replaced one is at '{}': take them from there",
                 final_path_.string(), policy_.kind, fmt::format("{}", fmt::join(not_carried, ", ")), old.string());
  } else if (!old.empty()) {
    RemoveAndUnregister(old);
    // The new output is in place; what is left of the old one (files this user may not delete) is said, not hidden.
    std::error_code ec;
    if (fs::exists(fs::symlink_status(old, ec))) {
      spdlog::warn(
          "the output '{}' replaced the old one, but the old one could not be removed all; what is left of it "
          "is in '{}': remove it yourself",
          final_path_.string(), old.string());
    }
  }
}

}  // namespace vmap
