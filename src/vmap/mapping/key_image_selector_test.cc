#include "vmap/mapping/key_image_selector.h"

#include <gtest/gtest.h>

#include "vmap/core/error.h"
#include "vmap/testing/option_error.h"

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
  std::vector<bool> below_tau;
  std::vector<std::pair<int, int>> evaluated;
};

// What the selector's LinkFn was told: the link's end and the S of the comparison it came with.
struct ReportedLink {
  int to_key;
  double comparison_similarity;
};

SelectionRun Select(int n, double tau, const std::function<double(int, int)>& similarity, bool final_key = true) {
  SelectionRun run;
  KeyImageOptions options;
  options.tau = tau;
  options.final_key = final_key;
  std::vector<ReportedLink> reported;
  KeyImageSelector selector(options, nullptr, nullptr, [&](const Link& link, const PairComparison& comparison) {
    reported.push_back({link.to_key, comparison.similarity});
  });
  const KeyImageSelector::CompareFn compare = [&](const FrameRecord& key, const FrameRecord& frame) {
    PairComparison c;
    const double s = similarity(key.frame->index, frame.frame->index);
    run.evaluated.emplace_back(key.frame->index, frame.frame->index);
    c.matched = s >= 0;
    c.similarity = c.matched ? s : 0.0;
    c.num_tentative = 100;
    c.num_verified = c.matched ? static_cast<int>(s * 100) : 0;
    return c;
  };
  for (int i = 0; i < n; ++i) selector.Add(Record(i), compare);
  selector.Finish();
  for (const KeyImage& k : selector.key_images()) run.keys.push_back(k.frame_index);
  for (const Link& l : selector.links()) {
    run.link_similarities.push_back(l.similarity);
    run.below_tau.push_back(l.below_tau);
    EXPECT_EQ(l.to_key, l.from_key + 1);
  }
  // Every link was reported once, as it was made, with the comparison it was made from.
  EXPECT_EQ(reported.size(), selector.links().size());
  for (size_t i = 0; i < reported.size() && i < selector.links().size(); ++i) {
    EXPECT_EQ(reported[i].to_key, static_cast<int>(i) + 1);
    EXPECT_EQ(reported[i].comparison_similarity, selector.links()[i].similarity);
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
  EXPECT_EQ(run.below_tau, std::vector<bool>(5, false));
}

TEST(KeyImageSelector, ThresholdIsInclusive) {
  // S == tau passes (the paper: a new key image when S < tau).
  const SelectionRun run = Select(4, 0.5, [](int, int) { return 0.5; });
  EXPECT_EQ(run.keys, (std::vector<int>{0, 3}));
}

TEST(KeyImageSelector, FrameThatMatchesNothingGivesLinksBelowTau) {
  // Frame 4 is black: nothing matches it.
  auto similarity = [](int key, int frame) { return (key == 4 || frame == 4) ? -1.0 : 0.9; };
  const SelectionRun run = Select(8, 0.5, similarity);
  EXPECT_EQ(run.keys, (std::vector<int>{0, 3, 4, 5, 7}));
  EXPECT_EQ(run.below_tau, (std::vector<bool>{false, true, true, false}));
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
  // Frame 2 fails against key 0 and frame 1 is promoted; then (1, 2) fails too: 2 becomes a key with a link
  // below tau, and is also the last frame: no duplicate final key image.
  const SelectionRun run = Select(3, 0.5, [](int key, int frame) { return frame == 2 ? 0.1 : 0.9; });
  EXPECT_EQ(run.keys, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(run.below_tau, (std::vector<bool>{false, true}));
}

// Frame i shows view views[i] (a repeated frame shows the same view as the one before it); S drops by 0.2
// per view of distance and the matches move 5 px per view.
std::vector<int> SelectViews(const std::vector<int>& views, double tau, double min_displacement,
                             std::vector<bool>* below_tau = nullptr, std::vector<std::string>* reasons = nullptr) {
  KeyImageOptions options;
  options.tau = tau;
  options.min_key_displacement = min_displacement;
  KeyImageSelector selector(options);
  const KeyImageSelector::CompareFn compare = [&](const FrameRecord& key, const FrameRecord& frame) {
    const int distance = std::abs(views[frame.frame->index] - views[key.frame->index]);
    PairComparison c;
    c.matched = true;
    c.similarity = 1.0 - 0.2 * distance;
    c.median_displacement = 5.0 * distance;
    c.num_tentative = 100;
    c.num_verified = static_cast<int>(100 * c.similarity);
    return c;
  };
  for (int i = 0; i < static_cast<int>(views.size()); ++i) selector.Add(Record(i), compare);
  selector.Finish();
  std::vector<int> keys;
  for (const KeyImage& k : selector.key_images()) {
    keys.push_back(k.frame_index);
    if (reasons) reasons->push_back(k.reason);
  }
  if (below_tau) {
    for (const Link& l : selector.links()) below_tau->push_back(l.below_tau);
  }
  return keys;
}

TEST(KeyImageSelector, RepeatedFramesAreNotPromotedWhenANeighbourWillDo) {
  // tau 0.7: a key image covers the next view only. Frame 1 repeats frame 0, frame 4 repeats frame 3.
  const std::vector<int> views = {0, 0, 2, 3, 3, 5, 6};
  // Algorithm 1 as published promotes frame 1 (the key image's own view again: a link without parallax),
  // then frame 2 fails against it as it did against frame 0 and is linked below tau.
  EXPECT_EQ(SelectViews(views, 0.7, 0.0), (std::vector<int>{0, 1, 2, 4, 5, 6}));
  // With the check, frame 1 is no candidate: frame 2 is linked to key 0 directly, below tau. Frame 4 repeats
  // frame 3, not the key image, and is promoted like any other frame.
  std::vector<bool> below_tau;
  std::vector<std::string> reasons;
  EXPECT_EQ(SelectViews(views, 0.7, 1.0, &below_tau, &reasons), (std::vector<int>{0, 2, 4, 5, 6}));
  EXPECT_EQ(below_tau, (std::vector<bool>{true, false, true, false}));
  EXPECT_NE(reasons[1].find("repeat the key image's view"), std::string::npos) << reasons[1];
  // A last frame back at the key image's view: the key image already is the route's goal (published: the
  // last frame becomes a final key image identical to key 0).
  EXPECT_EQ(SelectViews({0, 1, 0}, 0.7, 1.0), (std::vector<int>{0}));
  EXPECT_EQ(SelectViews({0, 1, 0}, 0.7, 0.0), (std::vector<int>{0, 2}));
  // Without repeats the check changes nothing.
  EXPECT_EQ(SelectViews({0, 1, 2, 3, 4, 5}, 0.7, 1.0), SelectViews({0, 1, 2, 3, 4, 5}, 0.7, 0.0));
  KeyImageOptions bad;
  bad.min_key_displacement = -1;
  EXPECT_EQ(testing::OptionErrorPath([&] { bad.Check(); }), "min_key_displacement");
}

// Algorithm 1's test: matched and S >= tau (inclusive); an unmatched pair never passes, whatever its S.
// S = verified / |D|: the paper's tables divide by the tentative matches, its text by the larger feature count.
TEST(PairComparison, SimilarityDenominatorFollowsTheMode) {
  EXPECT_EQ(SimilarityDenominator(SimilarityMode::kInlierRatio, 120, 500, 800), 120);
  EXPECT_EQ(SimilarityDenominator(SimilarityMode::kFeatureRatio, 120, 500, 800), 800);
  EXPECT_EQ(SimilarityDenominator(SimilarityMode::kFeatureRatio, 120, 900, 800), 900);
}

TEST(PairComparison, ReachesTauOnlyWhenMatchedAndSimilarEnough) {
  PairComparison c;
  c.matched = true;
  c.similarity = 0.4;
  EXPECT_TRUE(c.Reaches(0.4));
  EXPECT_TRUE(c.Reaches(0.3));
  EXPECT_FALSE(c.Reaches(0.41));
  c.matched = false;
  EXPECT_FALSE(c.Reaches(0.3));
}

TEST(KeyImageSelector, TauOutsideTheUnitIntervalIsRejected) {
  KeyImageOptions options;
  for (double tau : {0.0, -0.1, 1.01}) {
    options.tau = tau;
    EXPECT_EQ(testing::OptionErrorPath([&] { options.Check(); }), "tau") << tau;
  }
  options.tau = 1.0;
  EXPECT_NO_THROW(options.Check());
  EXPECT_THROW(ParseSimilarityMode("cosine"), InputError);
}

}  // namespace vmap

namespace vmap {

// The successor rule the builder's workers predict with is the one the selector follows (frames with a view
// of their own): frame 5 fails against key 0, so frame 4 follows; then frame 5 at once fails against key 4.
TEST(KeyImageSelector, SuccessorOfIsTheKeyImageTheSelectorChooses) {
  const SelectionRun run = Select(6, 0.5, [](int key, int frame) { return key == 0 && frame < 5 ? 0.9 : 0.1; });
  ASSERT_EQ(run.keys, (std::vector<int>{0, 4, 5}));
  EXPECT_EQ(KeyImageSelector::SuccessorOf(0, 5), 4);
  EXPECT_EQ(KeyImageSelector::SuccessorOf(4, 5), 5);  // the next frame already fails: linked below tau
  EXPECT_EQ(run.below_tau, (std::vector<bool>{false, true}));
}

}  // namespace vmap
