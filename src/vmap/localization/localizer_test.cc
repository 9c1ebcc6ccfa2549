#include "vmap/localization/localizer.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "vmap/core/error.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/geometry/chance_model.h"
#include "vmap/localization/localization_map.h"
#include "vmap/localization/localize_sequence.h"
#include "vmap/testing/localization_test_util.h"
#include "vmap/testing/option_error.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace {

using ::vmap::testing::DriveFrames;
using ::vmap::testing::DriveIndices;
using ::vmap::testing::SidewaysDrive;

// The map of the even frames, built once for all tests of this file.
struct EvenMap {
  ::vmap::testing::ScopedTempDir directory;
  LocalizationMap opened;
  EvenMap() {
    const auto matcher = CreateOrbMatcher({});
    MapBuilderOptions options;
    options.show_progress = false;
    ::vmap::testing::MemorySource source(DriveFrames(0, 2), DriveIndices(0, 2));
    ::vmap::testing::BuildMapDirectory(source, *matcher, options, directory.path() / "map");
    opened = OpenLocalizationMap(directory.path() / "map", {});
  }
};

const EvenMap& Map() {
  static const EvenMap map;
  return map;
}

Frame MakeFrame(const cv::Mat& image, int index, int source_index) {
  Frame frame;
  frame.index = index;
  frame.source_index = source_index;
  cv::cvtColor(image, frame.gray, cv::COLOR_BGR2GRAY);
  frame.color = image;
  return frame;
}

LocalizationResult LocalizeImage(Localizer& localizer, const cv::Mat& image, int index, int source_index) {
  const Frame frame = MakeFrame(image, index, source_index);
  const auto features = Map().opened.matcher->Extract(frame.gray);
  return localizer.Localize(frame, *features);
}

bool Brackets(const VisualMap& map, int source_index, int key) {
  const auto [before, after] = KeysAround(map, source_index);
  return key >= 0 && (key == before || key == after);
}

TEST(Localizer, TheMapHasSeveralKeyImages) {
  // The tests below are only meaningful with a route of several segments.
  EXPECT_GE(Map().opened.map.key_images.size(), 4u);
}

TEST(Localizer, EveryOddFrameIsLocalizedBetweenTheKeyImagesAroundIt) {
  const LocalizationMap& m = Map().opened;
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
  const LocalizationMap& m = Map().opened;
  Localizer localizer(m.map, m.keys, *m.matcher, MapLocalizerOptions(m));
  // Correlate the estimated progress with the true position between the two key images.
  std::vector<double> estimated, truth;
  const auto frames = DriveFrames(1, 2);
  const auto indices = DriveIndices(1, 2);
  for (size_t i = 0; i < frames.size(); ++i) {
    const LocalizationResult r = LocalizeImage(localizer, frames[i], static_cast<int>(i), indices[i]);
    const auto [before, after] = KeysAround(m.map, indices[i]);
    if (r.key != before || r.next_key != after || !std::isfinite(r.progress)) continue;
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

TEST(Localizer, RelocalizesAFrameFromTheMiddleAfterReset) {
  const LocalizationMap& m = Map().opened;
  Localizer localizer(m.map, m.keys, *m.matcher, MapLocalizerOptions(m));
  for (int source_index : {37, 11, 53, 25}) {
    localizer.Reset();
    ASSERT_FALSE(localizer.has_estimate());
    const LocalizationResult r = LocalizeImage(localizer, SidewaysDrive().frames[source_index], 0, source_index);
    EXPECT_EQ(r.status, LocalizationStatus::kRelocalized);
    EXPECT_TRUE(Brackets(m.map, source_index, r.key)) << "frame " << source_index << " at key " << r.key;
    EXPECT_FALSE(r.candidates.empty());
    EXPECT_TRUE(localizer.has_estimate());
  }
}

TEST(Localizer, AnUnrelatedImageIsLostAndTheEstimateIsDroppedAfterMaxLostFrames) {
  const LocalizationMap& m = Map().opened;
  LocalizerOptions options = MapLocalizerOptions(m);
  options.max_lost_frames = 2;
  // The tracker's own rule; the belief would place blind frames after a confident run at its best guess
  // (Localizer.FramesThatVerifyNothingAfterAConfidentRunAreCarriedByTheBelief).
  options.belief.window = 0;
  Localizer localizer(m.map, m.keys, *m.matcher, options);
  // Noise shares no scene point with the map.
  cv::Mat noise(SidewaysDrive().frames[0].size(), CV_8UC3);
  cv::RNG rng(3);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
  LocalizationResult r = LocalizeImage(localizer, noise, 0, 0);
  EXPECT_EQ(r.status, LocalizationStatus::kLost);
  EXPECT_EQ(r.key, -1);
  EXPECT_EQ(r.key_rank, -1) << "no key image: no rank";
  EXPECT_FALSE(MaySteerBy(r));
  EXPECT_EQ(r.next_key, -1);
  EXPECT_FALSE(localizer.has_estimate());

  r = LocalizeImage(localizer, SidewaysDrive().frames[21], 1, 21);
  EXPECT_EQ(r.status, LocalizationStatus::kRelocalized);
  const int key = r.key;
  for (int i = 0; i < 2; ++i) {
    r = LocalizeImage(localizer, noise, 2 + i, 0);
    EXPECT_EQ(r.status, LocalizationStatus::kLost);
    EXPECT_EQ(r.key, key) << "a lost frame keeps the last estimate";
    EXPECT_TRUE(localizer.has_estimate());
  }
  r = LocalizeImage(localizer, noise, 4, 0);
  EXPECT_EQ(r.status, LocalizationStatus::kLost);
  EXPECT_FALSE(localizer.has_estimate()) << "dropped after max_lost_frames + 1 lost frames in a row";
  // A frame inside a segment: one right after a key image is as much "at the end of the segment before" it
  // (RelocalizesAFrameFromTheMiddleAfterReset covers the choice between the two segments).
  r = LocalizeImage(localizer, SidewaysDrive().frames[33], 5, 33);
  EXPECT_EQ(r.status, LocalizationStatus::kRelocalized);
  EXPECT_TRUE(Brackets(m.map, 33, r.key));
}

// The drive's odd frames with all but a vertical strip `visible` of the width wide hidden behind noise: little
// of the scene is left, and the noise adds tentative matches that chance explains, so S is low.
std::vector<cv::Mat> MostlyHidden(double visible) {
  std::vector<cv::Mat> frames = DriveFrames(1, 2);
  cv::RNG rng(17);
  for (cv::Mat& frame : frames) {
    cv::Mat noise(frame.size(), frame.type());
    rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
    const int first_hidden = static_cast<int>(visible * frame.cols);
    const cv::Rect covered(first_hidden, 0, frame.cols - first_hidden, frame.rows);
    frame = frame.clone();
    noise(covered).copyTo(frame(covered));
  }
  return frames;
}

std::vector<LocalizationResult> LocalizeAll(const LocalizerOptions& options, std::vector<cv::Mat> frames,
                                            std::vector<int> indices) {
  const LocalizationMap& m = Map().opened;
  Localizer localizer(m.map, m.keys, *m.matcher, options);
  ::vmap::testing::MemorySource source(std::move(frames), std::move(indices));
  LocalizeSequenceOptions run;
  run.show_progress = false;
  std::vector<LocalizationResult> results;
  LocalizeSequence(source, *m.matcher, localizer, run,
                   [&](const Frame&, const LocalizationResult& r) { results.push_back(r); });
  return results;
}

TEST(Localizer, AFrameThatShowsLittleOfTheSceneIsStillLocalizedByItsChance) {
  // The earlier rule (S >= 0.3) loses frames that keep a few dozen verified matches among many chance ones;
  // the chance of those verified matches says they see the scene.
  const LocalizationMap& m = Map().opened;
  LocalizerOptions chance = MapLocalizerOptions(m);
  ASSERT_EQ(chance.acceptance, AcceptanceRule::kChance) << "the default";
  chance.min_link_share = 0.0;  // chance alone: the test is about its rule
  chance.min_heading_rival_ratio = 0.0;
  chance.belief.window = 0;  // frames placed by the acceptance rule, not by the belief's best guess
  LocalizerOptions counts = chance;
  counts.acceptance = AcceptanceRule::kCounts;
  const std::vector<LocalizationResult> by_chance = LocalizeAll(chance, MostlyHidden(0.35), DriveIndices(1, 2));
  const std::vector<LocalizationResult> by_counts = LocalizeAll(counts, MostlyHidden(0.35), DriveIndices(1, 2));
  ASSERT_EQ(by_chance.size(), 30u);
  int chance_localized = 0, bracketed = 0, counts_localized = 0, low_similarity = 0;
  for (size_t i = 0; i < by_chance.size(); ++i) {
    const LocalizationResult& r = by_chance[i];
    counts_localized += by_counts[i].status != LocalizationStatus::kLost;
    if (r.status == LocalizationStatus::kLost) continue;
    ++chance_localized;
    bracketed += Brackets(m.map, r.source_index, r.key);
    EXPECT_LE(r.to_key.log10_nfa, chance.max_log10_nfa);
    low_similarity += r.to_key.similarity < counts.min_similarity;
  }
  // The visible strip shares the far plane with key images well behind, so a frame may be placed there: it
  // does see them, but the bracket counts it wrong. Nearly all are at a key image around them.
  EXPECT_GE(10 * bracketed, 9 * chance_localized);
  EXPECT_GE(low_similarity, 3) << "frames S would have refused were localized";
  EXPECT_GT(bracketed, counts_localized) << "the earlier rule gives up on more of them";
  std::printf(
      "mostly hidden frames localized: %d by chance (%d at a key image around them), %d by counts; %d with "
      "S < %.1f\n",
      chance_localized, bracketed, counts_localized, low_similarity, counts.min_similarity);
}

TEST(Localizer, ASceneOfOtherTexturesIsNeverAccepted) {
  // The same kind of scene (planes with blobs and boxes, the same drive), other textures: nothing is shared,
  // though the images look alike and give ORB plenty of tentative matches.
  ::vmap::testing::SyntheticOptions other;
  other.num_frames = 60;
  other.step = 0.05;
  other.yaw_per_frame = 0.003;
  other.seed = 8;
  const auto elsewhere = ::vmap::testing::RenderSyntheticSequence(other);
  std::vector<cv::Mat> frames;
  std::vector<int> indices;
  for (int i = 1; i < other.num_frames; i += 2) {
    frames.push_back(elsewhere.frames[i]);
    indices.push_back(i);
  }
  LocalizerOptions chance = MapLocalizerOptions(Map().opened);
  chance.acceptance = AcceptanceRule::kChance;
  int candidates = 0;
  for (const LocalizationResult& r : LocalizeAll(chance, frames, indices)) {
    EXPECT_EQ(r.status, LocalizationStatus::kLost) << "frame " << r.source_index << " at key " << r.key;
    for (const RelocalizationCandidate& c : r.candidates) {
      EXPECT_FALSE(c.accepted);
      EXPECT_GT(c.log10_nfa, 0.0);
      ++candidates;
    }
  }
  EXPECT_GE(candidates, 30) << "every frame was relocalized against the best-ranked key images";
}

TEST(Localizer, FollowsAReversedRouteWhenTheFramesComeBackwards) {
  const LocalizationMap& m = Map().opened;
  LocalizerOptions options = MapLocalizerOptions(m);
  for (int k = static_cast<int>(m.map.key_images.size()) - 1; k >= 0; --k) options.route.push_back(k);
  Localizer localizer(m.map, m.keys, *m.matcher, options);
  int previous_key = static_cast<int>(m.map.key_images.size());
  int frame_index = 22;
  for (int source_index = 59; source_index > 0; source_index -= 2) {
    const LocalizationResult r =
        LocalizeImage(localizer, SidewaysDrive().frames[source_index], frame_index++, source_index);
    EXPECT_NE(r.status, LocalizationStatus::kLost) << "frame " << source_index;
    EXPECT_TRUE(Brackets(m.map, source_index, r.key)) << "frame " << source_index << " at key " << r.key;
    EXPECT_LE(r.key, previous_key);
    previous_key = r.key;
    if (r.next_key >= 0) {
      EXPECT_EQ(r.next_key, r.key - 1);
    }
  }
}

// A lost frame's relocalization is matched guided (LocalizerOptions::guided_relocalization): across lighting a frame
// the robot was carried to verifies nothing with cross-checked matches, at the tracked key images or at the ranking's
// best, while its one-way guided matches with the ranking's best pass chance (corridor_conditions' kidnapped run,
// repeat frame 24: key image 9 at log10 NFA +0.9 cross-checked, -10.3 guided). Here the far frame's first comparisons
// are given as chance refuses them, those at the tracked place below the link share too (guided matching there does
// not ask): the frame is relocalized where it is, and lost without the rule.
TEST(Localizer, ALostFramesRelocalizationIsMatchedGuidedAtTheRankingsBest) {
  const LocalizationMap& m = Map().opened;
  const int num_keys = static_cast<int>(m.map.key_images.size());
  for (const bool guided : {true, false}) {
    LocalizerOptions options = MapLocalizerOptions(m);
    ASSERT_TRUE(options.guided_relocalization) << "the default";
    options.guided_relocalization = guided;
    // Guided matching alone: compared again with more features, the frame is relocalized without it too.
    options.lost_frame_features = 0;
    // The tracker's own decisions: a far place taken on one frame (TakesJump), and no frame made uncertain.
    options.belief.window = 0;
    options.belief.min_confidence = 0.0;
    // The comparisons given stand for the frame's own, verified in full (a far one would be made again with fewer
    // iterations).
    options.far_comparison_iterations = 0;
    Localizer localizer(m.map, m.keys, *m.matcher, options);
    int index = 0;
    LocalizationResult r;
    for (int source_index : {1, 3, 5}) {
      r = LocalizeImage(localizer, SidewaysDrive().frames[source_index], index++, source_index);
    }
    ASSERT_EQ(r.status, LocalizationStatus::kTracking);
    const int tracked = r.route_position;
    const int far_frame = 51;
    ASSERT_FALSE(Brackets(m.map, far_frame, r.key)) << "a far place";
    std::vector<KeyComparison> refused;
    for (int key = 0; key < num_keys; ++key) {
      KeyComparison c;
      c.key = key;
      c.matched = true;
      c.num_tentative = 300;
      c.num_verified = std::abs(key - tracked) <= 2 ? 0 : 200;
      c.similarity = 0.1;
      c.log10_nfa = 5.0;
      refused.push_back(c);
    }
    const Frame frame = MakeFrame(SidewaysDrive().frames[far_frame], index++, far_frame);
    r = localizer.Localize(frame, *m.matcher->Extract(frame.gray), refused);
    if (guided) {
      EXPECT_EQ(r.status, LocalizationStatus::kRelocalized);
      EXPECT_TRUE(Brackets(m.map, far_frame, r.key)) << "at key " << r.key;
      const KeyComparison& accepted = r.to_key.accepted ? r.to_key : r.to_next;
      EXPECT_TRUE(accepted.accepted);
      EXPECT_LE(accepted.log10_nfa, options.max_log10_nfa);
    } else {
      EXPECT_EQ(r.status, LocalizationStatus::kLost);
    }
  }
}

// Near `key` the key image before it is compared too, in case the frame is behind `key`. Once that comparison
// finds it clearly worse, it is spared while the frame does not move back (here: the same frame again), and
// made again once the frame does (here: back at the previous key image, where the estimate must go).
TEST(Localizer, AStepBackRuledOutIsCheckedAgainOnceTheFrameMovesBack) {
  const LocalizationMap& m = Map().opened;
  const std::vector<KeyImage>& keys = m.map.key_images;
  ASSERT_GE(keys.size(), 4u);
  Localizer localizer(m.map, m.keys, *m.matcher, MapLocalizerOptions(m));
  const auto& frames = SidewaysDrive().frames;
  int frame_index = 0;
  auto localize = [&](int source_index) {
    return LocalizeImage(localizer, frames[source_index], frame_index++, source_index);
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
  const LocalizationMap& m = Map().opened;
  LocalizerOptions options = MapLocalizerOptions(m);
  const cv::Matx33d K = SidewaysDrive().K;
  options.camera = Camera::Make(K(0, 0), K(1, 1), K(0, 2), K(1, 2));
  Localizer localizer(m.map, m.keys, *m.matcher, options);
  const auto frames = DriveFrames(1, 2);
  const auto indices = DriveIndices(1, 2);
  int checked = 0;
  for (size_t i = 0; i < frames.size(); ++i) {
    const LocalizationResult r = LocalizeImage(localizer, frames[i], static_cast<int>(i), indices[i]);
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

TEST(Localizer, SameInputSameResults) {
  const LocalizationMap& m = Map().opened;
  std::vector<LocalizationResult> runs[2];
  for (auto& results : runs) {
    Localizer localizer(m.map, m.keys, *m.matcher, MapLocalizerOptions(m));
    for (int source_index : {9, 11, 13, 41, 43}) {
      results.push_back(LocalizeImage(localizer, SidewaysDrive().frames[source_index], 0, source_index));
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
  const Matcher& matcher = *Map().opened.matcher;
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
  const LocalizationMap& m = Map().opened;
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
  const LocalizationMap& m = Map().opened;
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
