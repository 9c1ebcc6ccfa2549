#pragma once
// What the pipelines may write, and over what: the folders they replace (a map, a sweep) and the inputs their
// single-file outputs (--csv, --json) must never overwrite (core/output_file.h's rule).

#include <string>
#include <vector>

#include "vmap/core/atomic_output.h"
#include "vmap/core/output_file.h"

namespace vmap {

// What a map's folder may replace: an empty folder or a map that vmap wrote, never one that is, holds or lies
// inside one of `inputs` (the recording, and any file the build reads: a camera file, a camera mask). A finished
// map that cannot be moved into place is kept beside it (OutputPolicy::keep_if_commit_fails). What the replaced
// folder held besides the map (the teach odometry, a user's notes, runs' outputs) moves into the new one.
OutputPolicy MapOutputPolicy(const std::vector<std::string>& inputs,
                             const std::vector<std::string>& files_beside_map = {});
// The same for a sweep's folder, which the sweep's `input` may not be, hold or lie inside.
OutputPolicy SweepOutputPolicy(const std::string& input);

// Every file of the map at `map_directory`, whether it exists yet or not: map.json, correspondences.bin,
// keys/, camera_mask.png, experiences/, teach_odometry.csv, the key-image cache, eval.json, report.html and what
// `vmap report` replaces in report/ (keys/, links/, the route video). Another name inside the map folder (an
// output written there by an earlier run) is not the map's, and may be written.
std::vector<OutputInput> MapInputs(const std::string& map_directory);

// A file or folder a pipeline reads, described by `what` for messages ("the query"); none when `path` is
// empty.
std::vector<OutputInput> NamedInput(const std::string& path, const std::string& what);
// Each of `paths` that exists, described by `what`: for options that name a file or give values instead (--camera
// takes a calibration file or "fx,fy,cx,cy").
std::vector<OutputInput> ExistingInputs(const std::vector<std::string>& paths, const std::string& what);

// CheckOutputFiles over the inputs put together, and over the files of any map an output lies in (a map's own
// files are never an output's, whichever command writes it). A pipeline names each output by its options field ({path,
// "csv"}): the refusal is an OptionError of that field, named by each front end as it names the field.
void CheckOutputs(const std::vector<OutputFile>& outputs, const std::vector<std::vector<OutputInput>>& inputs);

}  // namespace vmap
