#pragma once
// The inputs each command's single-file outputs (--csv, --json, -o FILE) must never overwrite, for the rule of
// core/output_file.h.

#include <string>
#include <vector>

#include "vmap/core/output_file.h"

namespace vmap::cli {

// Every file of the map at `map_directory`, whether it exists yet or not: map.json, correspondences.bin,
// keys/, the key-image cache, eval.json, report.html and report/. Another name inside the map folder (an
// output written there by an earlier run) is not the map's, and may be written.
std::vector<OutputInput> MapInputs(const std::string& map_directory);

// A file or folder the command reads, described by `what` for messages ("the query"); none when `path` is
// empty.
std::vector<OutputInput> NamedInput(const std::string& path, const std::string& what);

// CheckOutputFiles over the inputs put together.
void CheckOutputs(const std::vector<OutputFile>& outputs, const std::vector<std::vector<OutputInput>>& inputs);

}  // namespace vmap::cli
