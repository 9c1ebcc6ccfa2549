#pragma once
// The rule every single-file output of vmap follows (--csv, --json, -o FILE): it may replace only a regular
// file that is none of the command's inputs and none of the other outputs, and it is checked before any work,
// so that a refusal writes nothing. WriteFileAtomically checks the file again just before it renames over it.

#include <filesystem>
#include <string>
#include <vector>

namespace vmap {

// One output file and the option that names it: {"out.csv", "csv"} (a field's path, which a front end names
// its own way), or how the user named it ({"out.csv", "--csv"}).
struct OutputFile {
  std::filesystem::path path;
  std::string flag;
};

// An input, for messages: {"MAP/map.json", "the map's map.json"}. A folder input covers everything inside it.
struct OutputInput {
  std::filesystem::path path;
  std::string what;
};

// Whether two outputs that may not exist yet name the same file: the same inode, or the same path once links, "." and
// ".." are resolved.
bool SameOutput(const std::filesystem::path& a, const std::filesystem::path& b);

// Throws OptionError (an InputError) of the output's option, naming its path and what is in the way, when an
// output (those with an empty path are skipped):
// - resolves to an input or into a folder input (symbolic links, "..", hard links and bind mounts compared by
//   the files they reach), or to another of `outputs`;
// - exists and is a symbolic link, a device, a FIFO, a socket or a folder (vmap never renames over those);
// - exists and is not writable (read-only, or no write permission bit even for root);
// - exists and is a program (an ELF binary, a "#!" script): never an output of vmap's;
// - has a parent that is not an existing folder;
// - cannot be created there (a name too long, a folder this user may not write, a read-only file system): tried by
//   creating the output's temporary and removing it at once.
void CheckOutputFiles(const std::vector<OutputFile>& outputs, const std::vector<OutputInput>& inputs);

// Why the existing `path` may not be replaced by a regular file ("is a symbolic link; ..."), or "" when it may
// (it is a writable regular file, or absent). The part of CheckOutputFiles that WriteFileAtomically repeats.
std::string WhyNotReplaceable(const std::filesystem::path& path);

// Why an output whose name the system takes cannot be written all the same: vmap writes a temporary beside it first
// (.NAME.tmp-PID-N, .NAME.partial-PID-N), about 20 bytes longer, and a name holds at most 255 bytes.
inline constexpr const char* kNameTooLongForTemporary =
    "its name is too long for the temporary vmap writes beside it first (.NAME.tmp-PID-N, about 20 bytes longer; a "
    "file name holds 255 bytes): give a name of at most 230 bytes";

}  // namespace vmap
