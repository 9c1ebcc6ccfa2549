#pragma once
// Test helpers of the localization stage: a drive through a synthetic scene, and maps built in-process into a
// directory, as `vmap build` writes them (their frames come from a testing::MemorySource).

#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/features/matcher.h"
#include "vmap/mapping/batch_build.h"
#include "vmap/sources/frame_source.h"
#include "vmap/testing/memory_source.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap::testing {

// The localizer tests' drive: textured planes seen by a camera moving sideways with a little yaw (60 frames).
const SyntheticSequence& SidewaysDrive();
// Frames first, first + stride, ... up to `last` (-1: the end) of the drive, and their indices.
std::vector<cv::Mat> DriveFrames(int first, int stride, int last = -1);
std::vector<int> DriveIndices(int first, int stride, int last = -1);

// Builds a map of `source` with `matcher` into `directory` (created), key images and map files included.
VisualMap BuildMapDirectory(FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
                            const std::filesystem::path& directory);

// Runs `vmap localize MAP QUERY` twice through the binary (`arguments` added, e.g. --last): the first start must
// compute the key-image features and write the cache, the second read them from it, and both must localize
// every frame alike (everything in the --json output but times). `map` must have no cache yet.
void ExpectSecondLocalizeReadsTheCache(const std::filesystem::path& map, const std::filesystem::path& query,
                                       const std::string& arguments = "");

}  // namespace vmap::testing
