#include "vmap/map/map_writer.h"

#include <fstream>
#include <memory>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "vmap/map/map_io.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

std::shared_ptr<const Frame> GrayFrame(int index) {
  auto frame = std::make_shared<Frame>();
  frame->index = index;
  frame->source_index = index;
  frame->source_name = "frame_" + std::to_string(index);
  frame->gray = cv::Mat(48, 64, CV_8U, cv::Scalar(3 * index));
  return frame;
}

// A map of `num_key_images` key images (written through `writer`) linked in a row, over `num_frames` frames.
VisualMap ChainMap(MapWriter& writer, int num_key_images, int num_frames) {
  VisualMap map;
  map.input.path = "stream";
  map.input.format = SourceFormat::kVideo;
  map.input.frame_size = map.input.native_size = {64, 48};
  map.num_frames = num_frames;
  for (int k = 0; k < num_key_images; ++k) {
    KeyImage key;
    key.frame_index = key.source_index = k * (num_frames - 1) / std::max(1, num_key_images - 1);
    key.source_name = "frame_" + std::to_string(key.frame_index);
    key.image_file = writer.AddKeyImage(GrayFrame(key.frame_index));
    map.key_images.push_back(key);
    if (k == 0) continue;
    Link link;
    link.from_key = k - 1;
    link.to_key = k;
    link.num_tentative = 2;
    link.num_verified = 1;
    link.similarity = 0.5;
    link.correspondences = {{{1, 2}, {3, 4}}, {{5, 6}, {7, 8}}};
    map.links.push_back(link);
  }
  return map;
}

}  // namespace

TEST(MapWriter, EvaluationsGoToAFileNotToTheMapAndMapJsonHasThemAll) {
  testing::ScopedTempDir tmp;
  const fs::path directory = tmp.path() / "map";
  fs::create_directory(directory);
  MapWriter writer(directory);
  constexpr int kFrames = 5000;
  for (int f = 1; f < kFrames; ++f) writer.AddEvaluation({0, f, 1.0 / f, 100, 100 / f, f % 7 != 0});
  EXPECT_EQ(writer.num_evaluations(), kFrames - 1);
  EXPECT_TRUE(fs::exists(directory / kEvaluationsSpillFileName));
  VisualMap map = ChainMap(writer, 2, kFrames);
  ASSERT_TRUE(map.evaluations.empty());
  writer.Finish(map);
  EXPECT_FALSE(fs::exists(directory / kEvaluationsSpillFileName)) << "the file is the build's, not the map's";
  const VisualMap back = ReadMap(directory);
  ASSERT_EQ(back.evaluations.size(), static_cast<size_t>(kFrames - 1));
  EXPECT_EQ(back.evaluations[41].frame, 42);
  EXPECT_DOUBLE_EQ(back.evaluations[41].similarity, 1.0 / 42);
  EXPECT_FALSE(back.evaluations[6].matched);
  EXPECT_EQ(back.key_images[1].image_file, "keys/004999.png");
  EXPECT_EQ(cv::imread((directory / back.key_images[1].image_file).string()).size(), cv::Size(64, 48));
}

TEST(MapWriter, ASnapshotIsACompleteMapAtTheFinalPathAndTheBuildGoesOn) {
  testing::ScopedTempDir tmp;
  const fs::path final_path = tmp.path() / "live_map";
  OutputPolicy policy;
  policy.why_not_ours = WhyNotAVmapMap;
  AtomicOutputDirectory output(final_path, policy);
  MapWriter writer(output.path(), SnapshotTarget{final_path, policy, {}});
  for (int f = 1; f < 10; ++f) writer.AddEvaluation({0, f, 0.9, 10, 9, true});
  writer.Snapshot(ChainMap(writer, 2, 10));
  // The evaluations' file (flushed by the snapshot) holds the fields alone: not the struct with its padding,
  // whose bytes are never initialised.
  EXPECT_EQ(fs::file_size(output.path() / kEvaluationsSpillFileName), 9 * kEvaluationRecordSize);
  EXPECT_LT(kEvaluationRecordSize, sizeof(Evaluation));
  {
    const VisualMap snapshot = ReadMap(final_path);
    EXPECT_EQ(snapshot.num_frames, 10);
    EXPECT_EQ(snapshot.key_images.size(), 2u);
    EXPECT_EQ(snapshot.evaluations.size(), 9u);
    EXPECT_FALSE(fs::exists(final_path / kEvaluationsSpillFileName));
  }
  // The build goes on: more evaluations, a later snapshot replaces the first.
  for (int f = 10; f < 30; ++f) writer.AddEvaluation({9, f, 0.7, 10, 7, true});
  writer.Snapshot(ChainMap(writer, 3, 30));
  EXPECT_EQ(ReadMap(final_path).key_images.size(), 3u);
  EXPECT_EQ(ReadMap(final_path).evaluations.size(), 29u);
  // The end: the finished map replaces the last snapshot; nothing else is left beside it.
  VisualMap last = ChainMap(writer, 4, 30);
  writer.Finish(last);
  output.Commit();
  EXPECT_EQ(ReadMap(final_path).key_images.size(), 4u);
  EXPECT_EQ(std::distance(fs::directory_iterator(tmp.path()), fs::directory_iterator()), 1);
}

TEST(MapWriter, AnUnfinishedWriterRemovesItsEvaluationsFile) {
  testing::ScopedTempDir tmp;
  {
    MapWriter writer(tmp.path());
    writer.AddEvaluation({0, 1, 0.5, 2, 1, true});
    EXPECT_TRUE(fs::exists(tmp.path() / kEvaluationsSpillFileName));
  }
  EXPECT_FALSE(fs::exists(tmp.path() / kEvaluationsSpillFileName));
}

}  // namespace vmap
