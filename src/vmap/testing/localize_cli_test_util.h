#pragma once
// Test helpers of the `vmap localize` end-to-end tests (localization/localize*_cli_test.cc): the shared folder as a
// path, the lines and columns of the files a run writes, and which frames a run placed or steered by.

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace vmap::testing {

// SharedDir() as a path (empty without the shared data).
std::filesystem::path Shared();

// The lines of `file`, without their line ends.
std::vector<std::string> Lines(const std::filesystem::path& file);

// The cells of column `name` in a CSV `vmap localize` wrote, one a frame.
std::vector<std::string> CsvColumn(const std::filesystem::path& csv, const std::string& name);

// A frame (its CSV status and its key image or teach frame) placed on the route (tracking or relocalized), as
// bench/route_conditions.py counts it: where the goals ask the frame to be. A frame the agreement of its ranking and
// its heading places is placed but not steered by (guidance "none": AFrameTheEvidenceStepsOnIsNotSteeredByItsHeading);
// the tests count placed frames.
bool Placed(const std::pair<std::string, int>& frame);

// Runs `vmap localize ARGS -q --csv CSV` and returns the frames it placed (Placed): (source_index, key) each.
std::vector<std::pair<int, int>> SteeredFrames(const std::string& args, const std::filesystem::path& csv);

}  // namespace vmap::testing
