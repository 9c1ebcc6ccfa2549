#include "vmap/testing/localization_test_util.h"

#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "vmap/map/map_io.h"
#include "vmap/mapping/recorded_options.h"
#include "vmap/testing/run_vmap.h"

namespace vmap::testing {

VisualMap BuildMapDirectory(FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
                            const std::filesystem::path& directory) {
  std::filesystem::create_directories(directory);
  VisualMap map = BuildMap(source, matcher, options, directory, DescribeMapOptions(matcher, options, {}));
  WriteMapFiles(map, directory);
  return map;
}

void ExpectSecondLocalizeReadsTheCache(const std::filesystem::path& map, const std::filesystem::path& query,
                                       const std::string& arguments) {
  ASSERT_FALSE(std::filesystem::exists(map / "localization_cache.bin"));
  nlohmann::json runs[2];
  for (int run = 0; run < 2; ++run) {
    const std::filesystem::path json = map.parent_path() / ("localize" + std::to_string(run) + ".json");
    const CliResult r =
        RunVmap("localize " + Quote(map) + " " + Quote(query) + " " + arguments + " -q --json " + Quote(json));
    ASSERT_EQ(r.status, 0) << r.output;
    std::ifstream file(json);
    runs[run] = nlohmann::json::parse(file);
  }
  EXPECT_EQ(runs[0]["key_image_cache"], "written");
  EXPECT_EQ(runs[1]["key_image_cache"], "hit");
  ASSERT_EQ(runs[0]["frames"].size(), runs[1]["frames"].size());
  ASSERT_GT(runs[0]["frames"].size(), 0u);
  for (size_t i = 0; i < runs[0]["frames"].size(); ++i) {
    nlohmann::json a = runs[0]["frames"][i], b = runs[1]["frames"][i];
    a.erase("seconds");
    b.erase("seconds");
    EXPECT_EQ(a, b) << "frame " << i;
  }
}

const SyntheticSequence& SidewaysDrive() {
  static const SyntheticSequence sequence = [] {
    SyntheticOptions options;
    options.num_frames = 60;
    options.step = 0.05;
    options.yaw_per_frame = 0.003;
    return RenderSyntheticSequence(options);
  }();
  return sequence;
}

std::vector<int> DriveIndices(int first, int stride, int last) {
  std::vector<int> indices;
  const int end = last >= 0 ? last + 1 : static_cast<int>(SidewaysDrive().frames.size());
  for (int i = first; i < end; i += stride) indices.push_back(i);
  return indices;
}

std::vector<cv::Mat> DriveFrames(int first, int stride, int last) {
  std::vector<cv::Mat> frames;
  for (int i : DriveIndices(first, stride, last)) frames.push_back(SidewaysDrive().frames[i]);
  return frames;
}

}  // namespace vmap::testing
