// `vmap localize` with XFeat on corridor_conditions' repeat driven at one to four times the teach speed, with both
// runs' odometry (bench/route_conditions.py's speed-odometry-places set): the teach run as a recording of its own,
// frames 0.1 s and 0.1 m apart, built as a map of places (every third frame a key image); the repeat passing 1, 1, 2,
// 2, 3, 3, 4, 4, 4, 4, 3, 3, 2, 2, 1, 1 teach frames a frame, the camera at the teach run's rate, its odometry where
// its teach frames were. The fixture: xfeat_corridor_run.h.

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "vmap/neural/xfeat/xfeat_corridor_run.h"
#include "vmap/testing/localize_cli_test_util.h"
#include "vmap/testing/run_vmap.h"

namespace vmap::neural {
namespace {

namespace fs = std::filesystem;
using ::vmap::testing::Quote;

constexpr double kSecondsPerFrame = 0.1;  // both runs' frame times
constexpr double kMetresPerTeachFrame = 0.1;
constexpr int kTeachFrames = 111;

// A folder of links to `frames` numbered on from 0 with their times (timestamps.txt), and its odometry: frame f at
// `metres[f]` along a straight line.
void WriteTimedRun(const fs::path& folder, const std::vector<fs::path>& frames, const std::vector<double>& metres,
                   const fs::path& odometry) {
  fs::create_directories(folder);
  std::ofstream times(folder / "timestamps.txt");
  std::ofstream poses(odometry);
  poses << "timestamp,x,y,yaw\n";
  for (size_t f = 0; f < frames.size(); ++f) {
    char name[32];
    std::snprintf(name, sizeof(name), "%07zu.jpg", f);
    fs::create_symlink(frames[f], folder / name);
    times << name << " " << f * kSecondsPerFrame << "\n";
    poses << f * kSecondsPerFrame << "," << metres[f] << ",0,0\n";
  }
}

fs::path CorridorFrame(const fs::path& data, const std::string& run, int frame) {
  char name[32];
  std::snprintf(name, sizeof(name), "%07d.jpg", frame);
  return data / run / name;
}

class XfeatCorridorSpeedRun : public XfeatCorridorRun {
 protected:
  void SetUp() override {
    if (fs::exists(data_)) {
      std::vector<fs::path> frames;
      std::vector<double> metres;
      for (int i = 0; i < kTeachFrames; ++i) {
        frames.push_back(CorridorFrame(data_, "teach", i));
        metres.push_back(i * kMetresPerTeachFrame);
      }
      WriteTimedRun(Teach(), frames, metres, dir_.path() / "teach_odometry.csv");
    }
    XfeatCorridorRun::SetUp();
  }
  std::string BuildFlags() const override { return " --tau 1 --stride 3"; }
  fs::path Teach() const override { return dir_.path() / "timed_teach"; }

  // The repeat frames the run passes, one to four teach frames a frame (bench/route_conditions.py's speed sets).
  static std::vector<int> SpeedRun() {
    const int strides[] = {1, 1, 2, 2, 3, 3, 4, 4, 4, 4, 3, 3, 2, 2, 1, 1};
    std::vector<int> run;
    for (int i = 0; i < kTeachFrames; i += strides[(run.size() - 1) % 16]) run.push_back(i);
    return run;
  }

  // The frames steered by on the speed run from key image 0 with `flags`, with both runs' odometry.
  Steered SteeredOnSpeedRun(const std::string& flags) {
    const std::vector<int> repeat_of = SpeedRun();
    const fs::path run = dir_.path() / "speed_run";
    const fs::path odometry = dir_.path() / "speed_odometry.csv";
    if (!fs::exists(run)) {
      std::vector<fs::path> frames;
      std::vector<double> metres;
      for (int i : repeat_of) {
        frames.push_back(CorridorFrame(data_, "repeat", i));
        metres.push_back(i * kMetresPerTeachFrame);
      }
      WriteTimedRun(run, frames, metres, odometry);
    }
    Steered steered =
        testing::SteeredFrames(Quote(map_) + " " + Quote(run) + " --start-key 0 --teach-odometry " +
                                   Quote(dir_.path() / "teach_odometry.csv") + " --odometry " + Quote(odometry) + flags,
                               dir_.path() / "run.csv");
    for (auto& [frame, key] : steered) frame = repeat_of.at(frame);
    return steered;
  }
};

// A tracker behind the distance driven looks where the odometry says (docs/localize.md): at the verifier's seed 3 the
// run passes 1.3 key images a frame at its end (repeat frames 96-108), and key image 29 (teach frame 87), a look-alike
// of the route's end, verifies every frame there while the robot drives on: the tracker is held at it over the last
// three frames (right: 32-36). Where the distance driven since it reached 29 puts the robot, key images 33 and 35
// verify more, clearly, and the tracker steps on.
TEST_F(XfeatCorridorSpeedRun, ATrackerBehindTheDistanceDrivenLooksWhereTheOdometrySays) {
  // The lookahead by the pace reaches key images 33-35 on its own there: it is left out so that the test reaches the
  // case.
  ExpectNoFarFrameButWithout(" --driven-past-positions 0 --no-lookahead-by-pace",
                             "the tracker held at key image 29 to the route's end",
                             [&](const std::string& flags) { return SteeredOnSpeedRun(" --verifier-seed 3" + flags); });
}

// The distance driven vouches for the tracked key image (docs/localize.md): at the verifier's seed 7 the tracker steps
// on from key image 4 to 6 at run frame 8 (repeat frame 20, right: 6-8), where the odometry puts the robot, and the
// relocalization the frame is also asked for places it at key image 3, one verified match more: a near tie, taken
// back against the distance driven. The odometry keeps the tracker.
TEST_F(XfeatCorridorSpeedRun, TheDistanceDrivenVouchesForTheTrackedKeyImageAgainstANearTieElsewhere) {
  // The lookahead by the pace reaches key image 6 on its own there: it is left out so that the test reaches the case.
  ExpectNoFarFrameButWithout(" --driven-past-positions 0 --no-lookahead-by-pace",
                             "repeat frame 20 relocalized back at key image 3",
                             [&](const std::string& flags) { return SteeredOnSpeedRun(" --verifier-seed 7" + flags); });
}

}  // namespace
}  // namespace vmap::neural
