// The fixture of the XFeat corridor tests (xfeat_corridor_run.h).
#include "vmap/neural/xfeat/xfeat_corridor_run.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "vmap/testing/localize_cli_test_util.h"
#include "vmap/testing/run_vmap.h"

namespace vmap::neural {
namespace {

namespace fs = std::filesystem;
using ::vmap::testing::Quote;

std::string FoldedWeights() { return testing::SharedDir() + "/weights/xfeat/xfeat_folded.pt"; }

// The key images bracketing teach frame `frame` (the last at or before it, the first at or after it), of a map whose
// key images are teach frames `sources` (ascending).
std::vector<int> KeysAround(const std::vector<int>& sources, int frame) {
  std::vector<int> keys;
  for (int k = static_cast<int>(sources.size()) - 1; k >= 0; --k) {
    if (sources[k] <= frame) {
      keys.push_back(k);
      break;
    }
  }
  for (int k = 0; k < static_cast<int>(sources.size()); ++k) {
    if (sources[k] >= frame) {
      keys.push_back(k);
      break;
    }
  }
  return keys;
}

// The right key images of corridor_conditions' repeat frame `repeat`: those bracketing its teach frames i-2..i+2
// (bench/route_conditions.py's count).
std::vector<int> RightKeys(const std::vector<int>& sources, int repeat) {
  std::vector<int> keys;
  for (int j = repeat - 2; j <= repeat + 2; ++j) {
    for (int k : KeysAround(sources, j)) keys.push_back(k);
  }
  return keys;
}

}  // namespace

std::vector<int> CarriedRun(int from_first, int from_last, int to_first, int to_last) {
  std::vector<int> repeat_of;
  for (int i = from_first; i <= from_last; ++i) repeat_of.push_back(i);
  for (int i = to_first; i <= to_last; ++i) repeat_of.push_back(i);
  return repeat_of;
}

void XfeatCorridorRun::SetUp() {
  SKIP_WITHOUT_SHARED();
  if (!fs::exists(data_)) GTEST_SKIP() << data_ << " is not present";
  const auto built = testing::RunVmap("build " + Quote(Teach()) + " --matcher xfeat --weights " + FoldedWeights() +
                                      BuildFlags() + " -q -o " + Quote(map_));
  ASSERT_EQ(built.status, 0) << built.output;
  std::ifstream map_file(map_ / "map.json");
  const nlohmann::json map_json = nlohmann::json::parse(map_file);
  for (const auto& key : map_json["key_images"]) sources_.push_back(key["source_index"].get<int>());
  ASSERT_FALSE(sources_.empty());
}

int XfeatCorridorRun::KeyBefore(int frame) const { return KeysAround(sources_, frame).front(); }

XfeatCorridorRun::Steered XfeatCorridorRun::SteeredOnRepeat(int first, int last, int start_key,
                                                            const std::string& flags) {
  return testing::SteeredFrames(Quote(map_) + " " + Quote(data_ / "repeat") + " --first " + std::to_string(first) +
                                    " --last " + std::to_string(last) + " --start-key " + std::to_string(start_key) +
                                    flags,
                                dir_.path() / "run.csv");
}

XfeatCorridorRun::Steered XfeatCorridorRun::SteeredOnRun(const std::vector<int>& repeat_of, int start_key,
                                                         const std::string& flags) {
  const fs::path run = dir_.path() / "run";  // a folder of links to the repeat's frames, named in the run's order
  fs::remove_all(run);
  fs::create_directories(run);
  for (size_t f = 0; f < repeat_of.size(); ++f) {
    char name[32];
    std::snprintf(name, sizeof(name), "%07d.jpg", repeat_of[f]);
    char link[32];
    std::snprintf(link, sizeof(link), "%07zu.jpg", f);
    if (repeat_of[f] == kBlackFrame) {
      const cv::Mat first = cv::imread((data_ / "repeat" / "0000000.jpg").string());
      if (first.empty()) {
        ADD_FAILURE() << "corridor_conditions' repeat/0000000.jpg cannot be read";
        return {};
      }
      cv::imwrite((run / link).string(), cv::Mat::zeros(first.size(), first.type()));
      continue;
    }
    fs::create_symlink(data_ / "repeat" / name, run / link);
  }
  Steered steered = testing::SteeredFrames(
      Quote(map_) + " " + Quote(run) + " --start-key " + std::to_string(start_key) + flags, dir_.path() / "run.csv");
  for (auto& [frame, key] : steered) frame = repeat_of.at(frame);
  return steered;
}

int XfeatCorridorRun::Far(const Steered& steered) const {
  int far = 0;
  for (const auto& [frame, key] : steered) {
    int nearest = 1 << 20;
    for (int k : RightKeys(sources_, frame)) nearest = std::min(nearest, std::abs(key - k));
    far += nearest > 2;
  }
  return far;
}

int XfeatCorridorRun::Right(const Steered& steered) const {
  int right = 0;
  for (const auto& [frame, key] : steered) {
    const std::vector<int> keys = RightKeys(sources_, frame);
    right += std::find(keys.begin(), keys.end(), key) != keys.end();
  }
  return right;
}

void XfeatCorridorRun::ExpectNoFarFrameButWithout(const std::string& rule_off, const std::string& premise,
                                                  const std::function<Steered(const std::string&)>& steered) {
  EXPECT_EQ(Far(steered("")), 0);
  EXPECT_GE(Far(steered(rule_off)), 1) << "the test no longer reaches " << premise;
}

}  // namespace vmap::neural
