#include "vmap/pipelines/build_pipeline.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "vmap/features/matcher_registry.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/map/map_io.h"
#include "vmap/mapping/recorded_options.h"
#include "vmap/testing/localization_test_util.h"
#include "vmap/testing/option_error.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace {
namespace fs = std::filesystem;

BuildPipelineOptions Quiet(BuildPipelineOptions options) {
  options.map.show_progress = false;
  return options;
}

// A teach run written into FOLDER/teach, built into FOLDER/map with a snapshot after every frame.
BuildPipelineOptions SnapshotAfterEveryFrame(const fs::path& folder) {
  testing::WriteImageFolder(testing::SidewaysDrive(), folder / "teach");
  BuildPipelineOptions options;
  options.input = (folder / "teach").string();
  options.output = (folder / "map").string();
  options.snapshot_every = 1e-6;
  return options;
}

// The same teach run as a folder and as the host's own frames: the same map, committed where asked.
TEST(BuildPipeline, BuildsFromAPathOrFromTheHostsFramesAlike) {
  testing::ScopedTempDir tmp;
  testing::WriteImageFolder(testing::SidewaysDrive(), tmp.path() / "teach");
  BuildPipelineOptions options;
  options.input = (tmp.path() / "teach").string();
  options.output = (tmp.path() / "from_path").string();
  const BuildPipelineResult from_path = RunBuildPipeline(Quiet(options));
  EXPECT_EQ(from_path.directory, tmp.path() / "from_path");
  EXPECT_FALSE(from_path.interrupted);
  ASSERT_GE(from_path.map.key_images.size(), 2u);
  const RecordedMap read = ReadRecordedMap(tmp.path() / "from_path");
  EXPECT_EQ(read.map.key_images.size(), from_path.map.key_images.size());
  // τ unset: the matcher's own.
  EXPECT_EQ(read.options.builder.key_images.tau, DefaultTau("orb"));

  // The folder's images decoded as its source decodes them (grey, straight from the decoder).
  std::vector<cv::Mat> images;
  for (int i = 1; i <= from_path.map.num_frames; ++i) {
    images.push_back(
        cv::imread((tmp.path() / "teach" / ("frame_" + std::to_string(i) + ".png")).string(), cv::IMREAD_GRAYSCALE));
  }
  testing::MemorySource frames(images);
  options.output = (tmp.path() / "from_frames").string();
  const BuildPipelineResult from_frames = RunBuildPipeline(Quiet(options), &frames);
  ASSERT_EQ(from_frames.map.key_images.size(), from_path.map.key_images.size());
  for (size_t i = 0; i < from_path.map.key_images.size(); ++i) {
    EXPECT_EQ(from_frames.map.key_images[i].frame_index, from_path.map.key_images[i].frame_index);
  }
}

TEST(BuildPipeline, TauGivenIsRecordedAndAfterFrameSeesEveryFrame) {
  testing::ScopedTempDir tmp;
  testing::WriteImageFolder(testing::SidewaysDrive(), tmp.path() / "teach");
  BuildPipelineOptions options;
  options.input = (tmp.path() / "teach").string();
  options.output = (tmp.path() / "map").string();
  options.tau = 0.3;
  int frames = 0;
  options.map.after_frame = [&] { ++frames; };
  const BuildPipelineResult built = RunBuildPipeline(Quiet(options));
  EXPECT_EQ(frames, built.map.num_frames);
  EXPECT_EQ(ReadRecordedMap(tmp.path() / "map").options.builder.key_images.tau, 0.3);
}

// A teach run cannot be made again: a snapshot that cannot be written is a warning, not the run's end, and a
// finished map that cannot be put in place is kept beside it, where the error says.
TEST(BuildPipeline, NeitherAFailedSnapshotNorAFailedCommitLosesTheRun) {
  testing::ScopedTempDir tmp;
  BuildPipelineOptions options = SnapshotAfterEveryFrame(tmp.path());
  int frames = 0;
  bool taken = false;
  options.map.after_frame = [&] {
    ++frames;
    // Once a snapshot is there, the folder becomes someone else's: no snapshot nor the map may replace it.
    if (taken || !fs::exists(tmp.path() / "map/map.json")) return;
    taken = true;
    fs::remove_all(tmp.path() / "map");
    fs::create_directory(tmp.path() / "map");
    std::ofstream(tmp.path() / "map/notes.txt") << "mine";
  };
  std::string error;
  try {
    RunBuildPipeline(Quiet(options));
  } catch (const InputError& e) {
    error = e.what();
  }
  ASSERT_TRUE(taken);
  EXPECT_EQ(testing::ReadText(tmp.path() / "map/notes.txt"), "mine");
  const size_t at = error.find("kept at '");
  ASSERT_NE(at, std::string::npos) << error;
  const fs::path kept = error.substr(at + 9, error.find('\'', at + 9) - at - 9);
  const RecordedMap read = ReadRecordedMap(kept);
  EXPECT_EQ(read.map.num_frames, frames);
  EXPECT_GE(read.map.key_images.size(), 2u);
}

// The host's files ride with each snapshot and the map: at every frame, the folder on disk holds the file of the
// snapshot it holds, so a run killed between snapshots keeps both of the same moment.
TEST(BuildPipeline, TheHostsFilesAreInEverySnapshotAndInTheMap) {
  testing::ScopedTempDir tmp;
  BuildPipelineOptions options = SnapshotAfterEveryFrame(tmp.path());
  int frames = 0, written = 0;
  std::vector<int> snapshot_frames;  // the frame count in the host's file of each snapshot seen on disk
  options.map.after_frame = [&] {
    ++frames;
    if (!fs::exists(tmp.path() / "map/map.json")) return;
    snapshot_frames.push_back(std::stoi(testing::ReadText(tmp.path() / "map/host.txt")));
  };
  options.write_beside_map = [&](const fs::path& folder) {
    ++written;
    EXPECT_NE(folder, tmp.path() / "map");  // into the folder about to be committed, never the committed one
    std::ofstream(folder / "host.txt") << frames;
  };
  const BuildPipelineResult built = RunBuildPipeline(Quiet(options));
  ASSERT_GE(snapshot_frames.size(), 2u);
  for (size_t i = 1; i < snapshot_frames.size(); ++i) EXPECT_GE(snapshot_frames[i], snapshot_frames[i - 1]);
  EXPECT_GT(snapshot_frames.back(), snapshot_frames.front());
  EXPECT_GT(written, static_cast<int>(snapshot_frames.size()));  // the snapshots seen, and the map
  EXPECT_EQ(testing::ReadText(tmp.path() / "map/host.txt"), std::to_string(built.map.num_frames));
  EXPECT_EQ(ReadRecordedMap(tmp.path() / "map").map.num_frames, built.map.num_frames);
}

// A host's file is its run's own: a map rebuilt keeps what the folder held besides the map (the teach odometry a
// rebuild of the same run needs), but a host that writes the file itself (the ROS node's new teach run) keeps none of
// an earlier run's, even when it writes none this time (no odometry came).
TEST(BuildPipeline, AnEarlierRunsFileOfTheHostIsNotKeptByARunThatWritesIt) {
  testing::ScopedTempDir tmp;
  testing::WriteImageFolder(testing::SidewaysDrive(), tmp.path() / "teach");
  BuildPipelineOptions options;
  options.input = (tmp.path() / "teach").string();
  options.output = (tmp.path() / "map").string();
  RunBuildPipeline(Quiet(options));
  std::ofstream(tmp.path() / "map/teach_odometry.csv") << "timestamp,x,y,yaw\n0,0,0,0\n";
  std::ofstream(tmp.path() / "map/notes.txt") << "mine\n";
  RunBuildPipeline(Quiet(options));
  EXPECT_TRUE(fs::exists(tmp.path() / "map/teach_odometry.csv")) << "a rebuild keeps it";
  options.files_beside_map = {"teach_odometry.csv"};
  options.write_beside_map = [](const fs::path&) {};  // no odometry this run
  RunBuildPipeline(Quiet(options));
  EXPECT_FALSE(fs::exists(tmp.path() / "map/teach_odometry.csv")) << "an earlier run's odometry";
  EXPECT_EQ(testing::ReadText(tmp.path() / "map/notes.txt"), "mine\n");
}

// The output defaults to "<input name>_map" beside the working directory.
TEST(BuildPipeline, OutputDefaultsToTheInputsName) {
  BuildPipelineOptions options;
  options.input = "/data/teach.mp4";
  EXPECT_EQ(options.OutputDirectory(), fs::path("teach_map"));
  // A folder as tab completion writes it, or with a "." after it: its name, not "" (every such map was "_map").
  for (const char* folder : {"runs/run1/", "runs/run1/.", "runs/run1//", "runs/./run1"}) {
    options.input = folder;
    EXPECT_EQ(options.OutputDirectory(), fs::path("run1_map")) << folder;
  }
  options.input = ".";
  EXPECT_EQ(options.OutputDirectory(), fs::path(fs::current_path().filename().string() + "_map"));
  options.output = "elsewhere";
  EXPECT_EQ(options.OutputDirectory(), fs::path("elsewhere"));
}

// Bad options are named by their field and refused before any work: nothing is written.
TEST(BuildPipeline, BadOptionsNameTheirFieldAndWriteNothing) {
  testing::ScopedTempDir tmp;
  testing::WriteImageFolder(testing::SidewaysDrive(), tmp.path() / "teach");
  BuildPipelineOptions options;
  options.input = (tmp.path() / "teach").string();
  options.output = (tmp.path() / "map").string();
  auto path_of = [&](const std::function<void(BuildPipelineOptions&)>& change) {
    BuildPipelineOptions changed = options;
    change(changed);
    return testing::OptionErrorPath([&] { RunBuildPipeline(Quiet(changed)); });
  };
  EXPECT_EQ(path_of([](BuildPipelineOptions& o) { o.tau = 1.5; }), "tau");
  EXPECT_EQ(path_of([](BuildPipelineOptions& o) { o.snapshot_every = -1; }), "snapshot_every");
  EXPECT_EQ(path_of([](BuildPipelineOptions& o) { o.snapshot_every = 1, o.map.key_search = KeySearch::kBisect; }),
            "key_search");
  EXPECT_EQ(path_of([](BuildPipelineOptions& o) { o.source.stride = 0; }), "stride");
  EXPECT_EQ(path_of([](BuildPipelineOptions& o) { o.map.verifier.threshold = -1; }), "verifier.threshold");
  EXPECT_EQ(path_of([](BuildPipelineOptions& o) { o.matcher.Of<OrbMatcherOptions>().num_features = 0; }),
            "orb.num_features");
  EXPECT_FALSE(fs::exists(tmp.path() / "map"));
}

}  // namespace
}  // namespace vmap
