#pragma once
// Outputs are written so that an interrupted run never leaves a half-written file or map behind, and so that
// vmap never replaces anything it cannot prove it wrote:
// - everything goes to a temporary sibling first (".NAME.partial-PID-N", ".NAME.tmp-PID-N") and is renamed
//   into place at the end;
// - every temporary is registered while it exists, so that an interrupted run can remove them
//   (RemoveTemporaryOutputsForExit, called by the interrupt handling of interrupt.h);
// - a temporary left by a run that was killed outright (SIGKILL, power loss) is removed by the next run that
//   writes to the same place, once its PID no longer runs; a live process's temporaries are never touched;
// - an existing directory is replaced only when it is empty or its owner's proof says it is vmap's (a map
//   folder whose map.json is a vmap map, ...), and never when it is, holds or lies inside an input.

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace vmap {

// Writes `content` to `path` through a temporary file in the same directory and a rename. Never replaces a
// symbolic link, a device, a FIFO, a socket or a read-only file (InputError; see output_file.h).
// `completes`: TemporaryDirectory objects moved into place before this file, which this file makes part of
// the output (a map.json naming the views just moved in): they stop being temporary in the same step as the
// rename, so that an interruption removes them exactly when the file was not written.
class TemporaryDirectory;
void WriteFileAtomically(const std::filesystem::path& path, std::string_view content,
                         const std::vector<TemporaryDirectory*>& completes = {});

// WriteFileAtomically in two steps: the temporary file is written (and synced) when the object is made, and renamed
// into place by Commit(). A command with several outputs (`vmap localize --csv --json --report`) writes them all
// before it puts any in place, so that a failure while writing one (a full disk) replaces none of the earlier
// run's. Removed when destroyed uncommitted, or when the process is interrupted. Throws InputError as
// WriteFileAtomically does.
class PendingFile {
 public:
  PendingFile(std::filesystem::path path, std::string_view content);
  ~PendingFile();
  PendingFile(const PendingFile&) = delete;
  PendingFile& operator=(const PendingFile&) = delete;

  void Commit(const std::vector<TemporaryDirectory*>& completes = {});

 private:
  std::filesystem::path path_;
  std::filesystem::path temp_;  // empty once committed
  bool inside_temporary_ = false;
};

// A folder of this process's own work, ".NAME.partial-PID-N" beside `near` (NAME its file name), that becomes
// part of an output by a rename: an experience's views, written before they are moved into a map. It is
// removed when the object is destroyed or the process interrupted (wherever MoveTo put it) until a
// WriteFileAtomically completes it; one left by a killed process is removed by the next one made beside it.
class TemporaryDirectory {
 public:
  explicit TemporaryDirectory(const std::filesystem::path& near);
  ~TemporaryDirectory();
  TemporaryDirectory(const TemporaryDirectory&) = delete;
  TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;

  // Where it is now.
  const std::filesystem::path& path() const { return path_; }
  // Renames `from` (this folder, or a folder inside it, which then becomes what is removed on failure) to
  // `to`, which must not exist, and whose parent must be a real folder, not a symbolic link (its own path
  // resolved by the caller). Throws InputError naming `to`.
  void MoveTo(const std::filesystem::path& from, const std::filesystem::path& to);

 private:
  friend class PendingFile;
  std::filesystem::path path_;
  bool completed_ = false;
};

// What an output directory may replace, and what it must never touch.
struct OutputPolicy {
  // Proves that an existing, non-empty directory is one vmap wrote: returns "" when it is, or why it is not
  // ("its map.json is not a vmap map"), which the refusal shows. Null: only an absent or empty directory is
  // ever replaced. Core stays generic: the stage that writes the files knows how to recognise them.
  std::function<std::string(const std::filesystem::path& directory)> why_not_ours;
  // What such a directory is, for messages: "a vmap map".
  std::string kind = "a vmap output";
  // What the command reads. The output may not be one of them, hold one or lie inside one (compared as the
  // directories they resolve to, through symbolic links and bind mounts).
  std::vector<std::filesystem::path> inputs;

  // When the finished directory cannot be moved into place (the folder became unwritable or someone else's while
  // vmap worked), keep it under a visible sibling name, "NAME.unplaced-TIME", which the error names, instead of
  // removing it: for outputs that cost a run that cannot be made again (a teach run's map).
  bool keep_if_commit_fails = false;

  // Whether an entry of a replaced directory, by its name, is the output's own (a map's map.json, keys/). Its other
  // entries (a user's notes, a run's CSV, the teach odometry put beside a map) are moved into the new directory
  // where it holds none of that name, and said at info level: a rebuild keeps what it did not write. Null: the
  // replaced directory goes whole.
  std::function<bool(const std::string& name)> is_own_entry;

  // For a directory inside one already proven to be vmap's (a map's report/ assets): anything goes.
  static OutputPolicy InsideVmapOutput();
};

// A directory that only appears under its final name once Commit() is called. Until then the work happens
// in a hidden temporary sibling, removed if the object is destroyed uncommitted (or the process interrupted).
class AtomicOutputDirectory {
 public:
  // Checks the policy now (throws InputError saying why and what to do), so that a refusal comes before any
  // work, and again in Commit().
  AtomicOutputDirectory(std::filesystem::path final_path, OutputPolicy policy);
  ~AtomicOutputDirectory();
  AtomicOutputDirectory(const AtomicOutputDirectory&) = delete;
  AtomicOutputDirectory& operator=(const AtomicOutputDirectory&) = delete;

  // The directory to write into now. Create what goes inside it with create_directory, never
  // create_directories: an interruption removes this directory from another thread, and a recursive creation
  // racing with that removal would bring it back, to stay behind.
  const std::filesystem::path& path() const { return temp_path_; }
  const std::filesystem::path& final_path() const { return final_path_; }

  // Moves the finished directory into place, replacing an older one in one atomic step where the file system
  // can (renameat2 RENAME_EXCHANGE), so that the final path always holds a complete directory. Throws InputError
  // when it cannot (the directory is then removed, or kept: OutputPolicy::keep_if_commit_fails).
  void Commit();

 private:
  void MoveIntoPlace();
  // Keeps the uncommitted directory for the user (keep_if_commit_fails); returns the sentence saying where.
  std::string KeepUnplaced();
  void CheckReplaceable() const;
  static void CheckReplaceable(const std::filesystem::path& final_path, const OutputPolicy& policy);
  friend void CheckOutputDirectory(const std::filesystem::path& final_path, const OutputPolicy& policy);

  std::filesystem::path final_path_;
  OutputPolicy policy_;
  std::filesystem::path temp_path_;
  // The folders above the output that did not exist and were created for it, nearest first: an output that is
  // never committed takes them with it (where they are still empty), as `-o runs/today/map` of a failed run.
  std::vector<std::filesystem::path> created_parents_;
  bool committed_ = false;
};

// The check AtomicOutputDirectory makes before any work, without creating anything: for a command that
// writes the directory only at its end, to refuse a wrong one at its start. Throws InputError.
void CheckOutputDirectory(const std::filesystem::path& final_path, const OutputPolicy& policy);

// Removes the temporaries of dead processes next to `path` (".NAME.partial-PID-N" and the like, NAME being
// `path`'s file name). Called by every output before it writes; exposed for tests.
void RemoveStaleTemporaries(const std::filesystem::path& path);

// The pid of another live vmap process writing the output at `path` (its ".NAME.partial-PID-N" beside it: a build
// that will replace it), or 0.
long OtherWriterOf(const std::filesystem::path& path);

// Removes every temporary output this process still has, and keeps them from being created or committed from
// then on: for the last moments of an interrupted process only. Returns how many were removed.
int RemoveTemporaryOutputsForExit();

}  // namespace vmap
