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

// Whether a process with this pid exists (ours included; EPERM means it exists and is another user's).
bool ProcessRuns(long pid);

}  // namespace vmap
