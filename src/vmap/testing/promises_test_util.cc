#include "vmap/testing/promises_test_util.h"

#include <system_error>

#include <gtest/gtest.h>

#include "vmap/testing/run_vmap.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap::testing {

void WriteSyntheticInput(const std::filesystem::path& directory, int num_frames) {
  SyntheticOptions options;
  options.num_frames = num_frames;
  WriteImageFolder(RenderSyntheticSequence(options), directory);
}

void BuildMapWithBinary(const std::filesystem::path& input, const std::filesystem::path& directory,
                        const std::string& extra) {
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(input) + " -o " + Quote(directory) + " " + extra, &out), 0) << out;
}

std::vector<std::string> EntriesStartingWith(const std::filesystem::path& directory, const std::string& prefix) {
  std::vector<std::string> names;
  std::error_code ec;
  for (std::filesystem::directory_iterator it(directory, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind(prefix, 0) == 0) names.push_back(name);
  }
  return names;
}

}  // namespace vmap::testing
