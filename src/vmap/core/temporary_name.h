#pragma once
// The names of vmap's temporaries beside an output, ".NAME.TAG-PID-N": made, and read back to tell whose a leftover is
// (core/atomic_output.h removes those of dead processes).

#include <filesystem>
#include <string>

namespace vmap {

// A name for a temporary beside `path`, ".NAME.TAG-PID-N" (TAG: "partial", "old" or "tmp"): the pid says whose it
// is (RemoveStaleTemporaries), N keeps one process's apart. Nothing is created.
std::filesystem::path TemporarySibling(const std::filesystem::path& path, const char* tag);

// The pid in a temporary's name ".NAME.TAG-PID-N" of `name`, or 0 when `file_name` is not one.
long TemporaryOwner(const std::string& file_name, const std::string& name);

// `message` with each path into a temporary folder (".NAME.TAG-PID-N/keys/000000.png") named by the output it becomes
// ("NAME/keys/000000.png"): an error while a file was written names where the user looks for it, not a hidden folder
// that is gone once the message is read. A temporary named alone (where a finished output was kept) stays as it is.
std::string NameOutputsNotTemporaries(const std::string& message);

// Whether a process with this pid exists (ours included; EPERM means it exists and is another user's).
bool ProcessRuns(long pid);

}  // namespace vmap
