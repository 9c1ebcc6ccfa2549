// The Localizer along the sideways drive: its frames tracked between the key images around them, forwards and
// backwards, with the comparisons each frame needs and the same results however they are made; and its options.
#include "vmap/localization/localizer.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "vmap/core/error.h"
#include "vmap/geometry/chance_model.h"
#include "vmap/localization/localization_map.h"
#include "vmap/localization/localize_sequence.h"
#include "vmap/localization/still_frame.h"
#include "vmap/testing/localization_test_util.h"
#include "vmap/testing/localizer_test_util.h"
#include "vmap/testing/option_error.h"

namespace vmap {
namespace {

using ::vmap::testing::Brackets;
using ::vmap::testing::DenseDriveMap;
using ::vmap::testing::DriveFrames;
using ::vmap::testing::DriveIndices;
using ::vmap::testing::EvenDriveMap;
using ::vmap::testing::GivenComparison;
using ::vmap::testing::LocalizeFramesOnDenseMap;
using ::vmap::testing::LocalizeOnEvenMap;
using ::vmap::testing::SidewaysDrive;

TEST(Localizer, TheMapHasSeveralKeyImages) {
  // The tests below are only meaningful with a route of several segments.
  EXPECT_GE(EvenDriveMap().map.key_images.size(), 4u);
}

TEST(Localizer, EveryOddFrameIsLocalizedBetweenTheKeyImagesAroundIt) {
  const LocalizationMap& m = EvenDriveMap();
  Localizer localizer(m.map, m.keys, *m.matcher, MapLocalizerOptions(m));
  ::vmap::testing::MemorySource source(DriveFrames(1, 2), DriveIndices(1, 2));
  LocalizeSequenceOptions run;
  run.show_progress = false;
  std::vector<LocalizationResult> results;
  const LocalizationSummary summary = LocalizeSequence(
      source, *m.matcher, localizer, run, [&](const Frame&, const LocalizationResult& r) { results.push_back(r); });
  ASSERT_EQ(summary.frames, 30);
  EXPECT_EQ(results.front().status, LocalizationStatus::kRelocalized);
  EXPECT_EQ(summary.relocalized, 1);
  EXPECT_EQ(summary.lost, 0);
  EXPECT_EQ(summary.tracking, 29);
  int previous_key = 0, best_of_those_compared = 0;
  for (const LocalizationResult& r : results) {
    EXPECT_TRUE(Brackets(m.map, r.source_index, r.key)) << "frame " << r.source_index << " at key " << r.key;
    EXPECT_GE(r.key_rank, 1);
    EXPECT_LE(r.key_rank, r.comparisons);
    best_of_those_compared += r.key_rank == 1;
    EXPECT_GE(r.key, previous_key) << "the estimate only moves forwards along a forward drive";
    previous_key = r.key;
    EXPECT_EQ(r.next_key, r.key + 1 < static_cast<int>(m.map.key_images.size()) ? r.key + 1 : -1);
    EXPECT_TRUE(r.to_key.accepted);
    EXPECT_EQ(r.to_key.key, r.key);
    if (r.next_key >= 0) {
      // F maps the frame to the next key image: its verified matches satisfy it (checked through S > 0).
      EXPECT_TRUE(r.to_next.matched);
      EXPECT_NE(cv::norm(r.to_next.F), 0.0);
      EXPECT_TRUE(std::isfinite(r.progress));
      EXPECT_GE(r.progress, 0.0);
      EXPECT_LE(r.progress, 1.0);
    }
  }
  EXPECT_GE(best_of_those_compared, 25) << "the key image a frame is at is mostly the best match it was compared with";
}

TEST(Localizer, ProgressGrowsAlongASegment) {
  const LocalizationMap& m = EvenDriveMap();
  Localizer localizer(m.map, m.keys, *m.matcher, MapLocalizerOptions(m));
  // Correlate the estimated progress with the true position between the two key images.
  std::vector<double> estimated, truth;
  const auto frames = DriveFrames(1, 2);
  const auto indices = DriveIndices(1, 2);
  for (size_t i = 0; i < frames.size(); ++i) {
    const LocalizationResult r = LocalizeOnEvenMap(localizer, frames[i], static_cast<int>(i), indices[i]);
    const auto [before, after] = KeysAround(m.map, indices[i]);
    if (before < 0 || after <= before || r.key != before || r.next_key != after || !std::isfinite(r.progress)) continue;
    const double a = m.map.key_images[before].source_index, b = m.map.key_images[after].source_index;
    estimated.push_back(r.progress);
    truth.push_back((indices[i] - a) / (b - a));
  }
  ASSERT_GE(estimated.size(), 10u);
  cv::Mat e(estimated), t(truth), mean_e, std_e, mean_t, std_t;
  cv::meanStdDev(e, mean_e, std_e);
  cv::meanStdDev(t, mean_t, std_t);
  const double covariance = cv::mean((e - mean_e.at<double>(0)).mul(t - mean_t.at<double>(0)))[0];
  EXPECT_GT(covariance / (std_e.at<double>(0) * std_t.at<double>(0)), 0.5);
}

TEST(Localizer, FollowsAReversedRouteWhenTheFramesComeBackwards) {
  const LocalizationMap& m = EvenDriveMap();
  LocalizerOptions options = MapLocalizerOptions(m);
  for (int k = static_cast<int>(m.map.key_images.size()) - 1; k >= 0; --k) options.route.push_back(k);
  Localizer localizer(m.map, m.keys, *m.matcher, options);
  int previous_key = static_cast<int>(m.map.key_images.size());
  int frame_index = 22;
  for (int source_index = 59; source_index > 0; source_index -= 2) {
    const LocalizationResult r =
        LocalizeOnEvenMap(localizer, SidewaysDrive().frames[source_index], frame_index++, source_index);
    EXPECT_NE(r.status, LocalizationStatus::kLost) << "frame " << source_index;
    EXPECT_TRUE(Brackets(m.map, source_index, r.key)) << "frame " << source_index << " at key " << r.key;
    EXPECT_LE(r.key, previous_key);
    previous_key = r.key;
    if (r.next_key >= 0) {
      EXPECT_EQ(r.next_key, r.key - 1);
    }
  }
}

// Near `key` the key image before it is compared too, in case the frame is behind `key`. Once that comparison
// finds it clearly worse, it is spared while the frame does not move back (here: the same frame again), and
// made again once the frame does (here: back at the previous key image, where the estimate must go).
TEST(Localizer, AStepBackRuledOutIsCheckedAgainOnceTheFrameMovesBack) {
  const LocalizationMap& m = EvenDriveMap();
  const std::vector<KeyImage>& keys = m.map.key_images;
  ASSERT_GE(keys.size(), 4u);
  Localizer localizer(m.map, m.keys, *m.matcher, MapLocalizerOptions(m));
  const auto& frames = SidewaysDrive().frames;
  int frame_index = 0;
  auto localize = [&](int source_index) {
    return LocalizeOnEvenMap(localizer, frames[source_index], frame_index++, source_index);
  };
  const int k = 2;
  const int at = keys[k].source_index;
  localize(at - 1);  // relocalized just before key image k
  localize(at);      // at it: moved on to it (no step back is checked on a frame that moves on)
  const LocalizationResult checked = localize(at);
  const LocalizationResult spared = localize(at);
  const LocalizationResult behind = localize(at - 2);
  ASSERT_EQ(checked.key, k);
  ASSERT_EQ(checked.status, LocalizationStatus::kTracking);
  EXPECT_EQ(checked.comparisons, 3) << "key, next_key and the key image before key";
  EXPECT_EQ(spared.key, k);
  EXPECT_EQ(spared.to_key.num_verified, checked.to_key.num_verified);
  EXPECT_EQ(spared.to_next.num_verified, checked.to_next.num_verified);
  EXPECT_EQ(spared.comparisons, 2) << "the same frame again: not behind key";
  ASSERT_LT(behind.to_next.num_verified, checked.to_next.num_verified) << "the test's frame must have moved back";
  EXPECT_EQ(behind.comparisons, 3) << "moved back: checked again";
  EXPECT_EQ(behind.key, k);
}

// A pose costs as much as a verification, and only the target's guides the robot: the other comparisons carry
// their verified matches, from which AddPose gives the same pose on demand.
TEST(Localizer, OnlyTheTargetComparisonIsPosed) {
  const LocalizationMap& m = EvenDriveMap();
  LocalizerOptions options = MapLocalizerOptions(m);
  const cv::Matx33d K = SidewaysDrive().K;
  options.camera = Camera::Make(K(0, 0), K(1, 1), K(0, 2), K(1, 2));
  Localizer localizer(m.map, m.keys, *m.matcher, options);
  const auto frames = DriveFrames(1, 2);
  const auto indices = DriveIndices(1, 2);
  int checked = 0;
  for (size_t i = 0; i < frames.size(); ++i) {
    const LocalizationResult r = LocalizeOnEvenMap(localizer, frames[i], static_cast<int>(i), indices[i]);
    if (r.next_key < 0 || !r.to_key.matched || !r.to_next.matched) continue;
    ++checked;
    EXPECT_TRUE(r.to_next.pose.valid) << "frame " << indices[i];
    EXPECT_FALSE(r.to_key.pose.valid) << "frame " << indices[i];
    EXPECT_TRUE(std::isnan(r.to_key.translation_sigma_deg));
    ASSERT_EQ(static_cast<int>(r.to_key.verified.size()), r.to_key.num_verified);
    // The verified matches are the frame's (p0) against the key image's (p1), on F's epipolar lines.
    std::vector<double> distances;
    for (const Correspondence& c : r.to_key.verified) distances.push_back(EpipolarDistance(r.to_key.F, c.p0, c.p1));
    std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
    EXPECT_LT(distances[distances.size() / 2], 1.0);
    KeyComparison posed = r.to_key;
    localizer.AddPose(posed);
    EXPECT_TRUE(posed.pose.valid);
    EXPECT_TRUE(std::isfinite(posed.translation_sigma_deg));
  }
  EXPECT_GE(checked, 20);
}

// ORB's comparisons with key images away from the tracker's (LocalizerOptions::far_comparison_iterations) are verified
// with fewer MAGSAC iterations; those of the tracker's own key images, and every one of a frame without an estimate, in
// full. Here the cap is one iteration, which verifies fewer matches than the full run at some far key image: a frame
// tracked near the start, then a frame from far along the route, its tracked key images given refused, relocalized;
// its far candidates are as Compare gives them with that cap. Without an estimate, as Compare gives them in full.
TEST(Localizer, TheComparisonsAwayFromTheTrackerAreVerifiedWithFewerIterations) {
  const LocalizationMap& m = DenseDriveMap();
  LocalizerOptions options = MapLocalizerOptions(m);
  options.far_comparison_iterations = 1;
  // The candidates as first compared: not compared again guided or with more features.
  options.guided_relocalization = false;
  options.lost_frame_features = 0;
  options.belief.window = 0;  // the tracker's own decisions
  options.belief.min_confidence = 0.0;
  Localizer localizer(m.map, m.keys, *m.matcher, options);
  int index = 0;
  LocalizationResult r = LocalizeFramesOnDenseMap(localizer, {1, 3, 5}, &index);
  ASSERT_EQ(r.status, LocalizationStatus::kTracking);
  const int tracked = r.route_position;  // the route is the key images in order
  const int last_near = tracked + options.lookahead + 1;
  const int far_frame = 51;
  std::vector<KeyComparison> refused;
  for (int key = std::max(0, tracked - 1); key <= last_near; ++key)
    refused.push_back(GivenComparison(key, false, 0, 0));
  ::vmap::testing::MemorySource source({SidewaysDrive().frames[far_frame]}, {far_frame});
  Frame frame = *source.Next();
  frame.index = index++;
  const auto features = m.matcher->Extract(frame.gray);
  r = localizer.Localize(frame, *features, refused);
  int far = 0, capped_differs = 0;
  for (const RelocalizationCandidate& c : r.candidates) {
    if (c.key >= tracked - 1 && c.key <= last_near) continue;  // given
    const KeyComparison expected = localizer.Compare(*features, c.key, options.far_comparison_iterations);
    EXPECT_EQ(c.num_verified, expected.num_verified) << "key " << c.key;
    EXPECT_EQ(c.log10_nfa, expected.log10_nfa) << "key " << c.key;
    ++far;
    capped_differs += localizer.Compare(*features, c.key).num_verified != expected.num_verified;
  }
  ASSERT_GT(far, 0) << "relocalized at far key images";
  ASSERT_GT(capped_differs, 0) << "one iteration verifies as many as the full run: the test cannot tell";
  localizer.Reset();
  ASSERT_FALSE(localizer.has_estimate());
  r = localizer.Localize(frame, *features);
  ASSERT_FALSE(r.candidates.empty());
  for (const RelocalizationCandidate& c : r.candidates) {
    EXPECT_EQ(c.num_verified, localizer.Compare(*features, c.key).num_verified) << "key " << c.key;
  }
}

TEST(Localizer, SameInputSameResults) {
  const LocalizationMap& m = EvenDriveMap();
  std::vector<LocalizationResult> runs[2];
  for (auto& results : runs) {
    Localizer localizer(m.map, m.keys, *m.matcher, MapLocalizerOptions(m));
    for (int source_index : {9, 11, 13, 41, 43}) {
      results.push_back(LocalizeOnEvenMap(localizer, SidewaysDrive().frames[source_index], 0, source_index));
    }
  }
  for (size_t i = 0; i < runs[0].size(); ++i) {
    EXPECT_EQ(runs[0][i].key, runs[1][i].key);
    EXPECT_EQ(runs[0][i].to_key.num_verified, runs[1][i].to_key.num_verified);
    EXPECT_EQ(runs[0][i].to_next.num_verified, runs[1][i].to_next.num_verified);
    EXPECT_EQ(runs[0][i].heading_px, runs[1][i].heading_px);
  }
}

// The test of standing still that keeps a lost frame's weak heading from stepping a stopped robot on
// (LocalizerOptions::still_frame_share): the same image again, or a copy with a camera's noise, stands still against
// it; the next frame of a drive, a few pixels on, does not; nor does anything with the share 0.
TEST(Localizer, AFrameStandsStillAgainstItsOwnImageOrANoisyCopyNotTheNextFrame) {
  const Matcher& matcher = *EvenDriveMap().matcher;
  const auto features_of = [&](const cv::Mat& bgr) {
    cv::Mat gray;
    cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
    return matcher.Extract(gray);
  };
  const cv::Mat& image = SidewaysDrive().frames[20];
  cv::Mat noise(image.size(), CV_16SC3), noisy;
  cv::RNG(20).fill(noise, cv::RNG::UNIFORM, -6, 7);
  image.convertTo(noisy, CV_16SC3);
  cv::Mat(noisy + noise).convertTo(noisy, CV_8UC3);  // saturated
  const auto frame = features_of(image), again = features_of(image), copy = features_of(noisy),
             next = features_of(SidewaysDrive().frames[21]);
  const double share = LocalizerOptions().still_frame_share;
  EXPECT_TRUE(StandsStill(matcher, *frame, *again, share));
  EXPECT_TRUE(StandsStill(matcher, *frame, *copy, share));
  EXPECT_FALSE(StandsStill(matcher, *frame, *next, share));
  EXPECT_FALSE(StandsStill(matcher, *frame, *again, 0.0));
}

TEST(Localizer, ComparingAheadOnTheWorkersChangesNothing) {
  const LocalizationMap& m = EvenDriveMap();
  std::vector<LocalizationResult> runs[2];
  for (int i = 0; i < 2; ++i) {
    Localizer localizer(m.map, m.keys, *m.matcher, MapLocalizerOptions(m));
    ::vmap::testing::MemorySource source(DriveFrames(1, 2), DriveIndices(1, 2));
    LocalizeSequenceOptions run;
    run.show_progress = false;
    run.compare_ahead = i == 1;
    LocalizeSequence(source, *m.matcher, localizer, run,
                     [&](const Frame&, const LocalizationResult& r) { runs[i].push_back(r); });
  }
  ASSERT_EQ(runs[0].size(), runs[1].size());
  for (size_t f = 0; f < runs[0].size(); ++f) {
    const LocalizationResult &a = runs[0][f], &b = runs[1][f];
    EXPECT_EQ(a.status, b.status);
    EXPECT_EQ(a.key, b.key);
    EXPECT_EQ(a.next_key, b.next_key);
    EXPECT_EQ(a.to_key.num_verified, b.to_key.num_verified);
    EXPECT_EQ(a.to_next.num_verified, b.to_next.num_verified);
    EXPECT_EQ(a.to_next.F, b.to_next.F);
    EXPECT_EQ(a.heading_px, b.heading_px);
    EXPECT_EQ(a.comparisons, b.comparisons);
    // Bit for bit: the belief sums the frame's comparisons in the order the localizer asked for them.
    EXPECT_EQ(std::isnan(a.confidence), std::isnan(b.confidence)) << "frame " << f;
    if (!std::isnan(a.confidence)) {
      EXPECT_EQ(a.confidence, b.confidence) << "frame " << f;
    }
    EXPECT_EQ(a.belief, b.belief) << "frame " << f;
    EXPECT_EQ(a.key_rank, b.key_rank) << "frame " << f;
    EXPECT_EQ(LocalizationGuidance(a), LocalizationGuidance(b)) << "frame " << f;
  }
}

TEST(Localizer, OptionsAreChecked) {
  const LocalizationMap& m = EvenDriveMap();
  auto with = [&](auto change) {
    LocalizerOptions options = MapLocalizerOptions(m);
    change(options);
    return options;
  };
  auto path = [&](auto change) { return testing::OptionErrorPath([&] { with(change).Check(); }); };
  EXPECT_EQ(path([](LocalizerOptions& o) { o.min_verified = 5; }), "min_verified");
  EXPECT_EQ(path([](LocalizerOptions& o) { o.comparison_threads = 0; }), "comparison_threads");
  EXPECT_EQ(path([](LocalizerOptions& o) { o.lost_frame_features = -1; }), "lost_frame_features");
  EXPECT_EQ(path([](LocalizerOptions& o) { o.min_similarity = 1.5; }), "min_similarity");
  EXPECT_EQ(path([](LocalizerOptions& o) { o.max_log10_nfa = std::nan(""); }), "max_log10_nfa");
  EXPECT_EQ(path([](LocalizerOptions& o) { o.recheck_link_share = -0.1; }), "recheck_link_share");
  EXPECT_EQ(path([](LocalizerOptions& o) { o.min_link_share = std::nan(""); }), "min_link_share");
  EXPECT_EQ(path([](LocalizerOptions& o) { o.min_rival_ratio = 0.5; }), "min_rival_ratio");
  EXPECT_EQ(path([](LocalizerOptions& o) { o.rival_max_log10_nfa = 1.0; }), "rival_max_log10_nfa");
  EXPECT_EQ(path([](LocalizerOptions& o) { o.lookahead = 3; }), "lookahead");
  EXPECT_EQ(path([](LocalizerOptions& o) { o.max_lost_frames = -1; }), "max_lost_frames");
  EXPECT_EQ(path([](LocalizerOptions& o) { o.relocalization_candidates = 0; }), "relocalization_candidates");
  EXPECT_EQ(path([](LocalizerOptions& o) { o.ranking.min_cosine = 1.0; }), "ranking.min_cosine");
  EXPECT_EQ(path([](LocalizerOptions& o) { o.verifier.threshold = 0.0; }), "verifier.threshold");
  EXPECT_NO_THROW(with([](LocalizerOptions&) {}).Check());
  // A route must name existing key images, once each.
  LocalizerOptions bad_route = MapLocalizerOptions(m);
  bad_route.route = {0, 99};
  EXPECT_THROW(Localizer(m.map, m.keys, *m.matcher, bad_route), InputError);
  bad_route.route = {0, 1, 0};
  EXPECT_THROW(Localizer(m.map, m.keys, *m.matcher, bad_route), InputError);
}

}  // namespace
}  // namespace vmap
