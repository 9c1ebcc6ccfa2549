#include "vmap/mapping/key_image_selector.h"

#include <gtest/gtest.h>

#include "vmap/core/error.h"

namespace vmap {

namespace {

class CountingFeatures : public ImageFeatures {
 public:
  int num_features() const override { return 100; }
  cv::Size image_size() const override { return {64, 48}; }
};

FrameRecord Record(int index) {
  auto frame = std::make_shared<Frame>();
  frame->index = index;
  frame->source_index = index;
  frame->source_name = "f" + std::to_string(index);
  return {frame, std::make_shared<CountingFeatures>()};
}

// Runs the selector over `n` frames with a scripted similarity S(key, frame); < 0 means matching failed.
struct SelectionRun {
  std::vector<int> keys;
  std::vector<double> link_similarities;
  std::vector<bool> broken;
  std::vector<std::pair<int, int>> evaluated;
};

SelectionRun Select(int n, double tau, const std::function<double(int, int)>& similarity, bool final_key = true) {
  SelectionRun run;
  KeyImageOptions options;
  options.tau = tau;
  options.final_key = final_key;
  KeyImageSelector selector(options, [&](const FrameRecord& key, const FrameRecord& frame) {
    PairComparison c;
    const double s = similarity(key.frame->index, frame.frame->index);
    run.evaluated.emplace_back(key.frame->index, frame.frame->index);
    c.matched = s >= 0;
    c.similarity = c.matched ? s : 0.0;
    c.num_tentative = 100;
    c.num_verified = c.matched ? static_cast<int>(s * 100) : 0;
    return c;
  });
  for (int i = 0; i < n; ++i) selector.Add(Record(i));
  selector.Finish();
  for (const KeyImage& k : selector.key_images()) run.keys.push_back(k.frame_index);
  for (const Link& l : selector.links()) {
    run.link_similarities.push_back(l.similarity);
    run.broken.push_back(l.broken);
    EXPECT_EQ(l.to_key, l.from_key + 1);
  }
  EXPECT_EQ(selector.evaluations().size(), run.evaluated.size());
  EXPECT_EQ(selector.num_frames(), n);
  return run;
}

}  // namespace

TEST(KeyImageSelector, PreviousFrameBecomesKeyWhenSimilarityDrops) {
  // S decays by 0.1 per frame of distance: with tau 0.75 a key image covers two more frames.
  const SelectionRun run = Select(10, 0.75, [](int key, int frame) { return 1.0 - 0.1 * (frame - key); });
  EXPECT_EQ(run.keys, (std::vector<int>{0, 2, 4, 6, 8, 9}));
  ASSERT_EQ(run.link_similarities.size(), 5u);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(run.link_similarities[i], 0.8, 1e-12);
  EXPECT_NEAR(run.link_similarities[4], 0.9, 1e-12);  // the final key image, one frame after key 8
  // Every frame is compared, and a failing frame is compared again with the new key image.
  const std::vector<std::pair<int, int>> expected = {{0, 1}, {0, 2}, {0, 3}, {2, 3}, {2, 4}, {2, 5}, {4, 5},
                                                     {4, 6}, {4, 7}, {6, 7}, {6, 8}, {6, 9}, {8, 9}};
  EXPECT_EQ(run.evaluated, expected);
  EXPECT_EQ(run.broken, std::vector<bool>(5, false));
}

TEST(KeyImageSelector, ThresholdIsInclusive) {
  // S == tau passes (the paper: a new key image when S < tau).
  const SelectionRun run = Select(4, 0.5, [](int, int) { return 0.5; });
  EXPECT_EQ(run.keys, (std::vector<int>{0, 3}));
}

TEST(KeyImageSelector, FrameThatMatchesNothingGivesBrokenLinks) {
  // Frame 4 is black: nothing matches it.
  auto similarity = [](int key, int frame) { return (key == 4 || frame == 4) ? -1.0 : 0.9; };
  const SelectionRun run = Select(8, 0.5, similarity);
  EXPECT_EQ(run.keys, (std::vector<int>{0, 3, 4, 5, 7}));
  EXPECT_EQ(run.broken, (std::vector<bool>{false, true, true, false}));
  EXPECT_EQ(run.link_similarities[1], 0.0);
  const SelectionRun no_final = Select(8, 0.5, similarity, /*final_key=*/false);
  EXPECT_EQ(no_final.keys, (std::vector<int>{0, 3, 4, 5}));
}

TEST(KeyImageSelector, OneFrameIsAMapWithOneKeyImage) {
  const SelectionRun run = Select(1, 0.5, [](int, int) { return 1.0; });
  EXPECT_EQ(run.keys, std::vector<int>{0});
  EXPECT_TRUE(run.link_similarities.empty());
}

TEST(KeyImageSelector, LastFrameIsAlreadyKeyImage) {
  // Frame 2 fails against key 0 and frame 1 is promoted; then (1, 2) fails too: 2 becomes a key with a broken
  // link, and is also the last frame: no duplicate final key image.
  const SelectionRun run = Select(3, 0.5, [](int key, int frame) { return frame == 2 ? 0.1 : 0.9; });
  EXPECT_EQ(run.keys, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(run.broken, (std::vector<bool>{false, true}));
}

TEST(KeyImageSelector, TauOutsideTheUnitIntervalIsRejected) {
  KeyImageOptions options;
  for (double tau : {0.0, -0.1, 1.01}) {
    options.tau = tau;
    EXPECT_THROW(options.Check(), InputError) << tau;
  }
  options.tau = 1.0;
  EXPECT_NO_THROW(options.Check());
  EXPECT_THROW(ParseSimilarityMode("cosine"), InputError);
}

}  // namespace vmap
