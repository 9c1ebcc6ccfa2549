#include "vmap/localization/key_image_ranking.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "vmap/core/error.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace {

const ::vmap::testing::SyntheticSequence& Drive() {
  static const auto sequence = [] {
    ::vmap::testing::SyntheticOptions options;
    options.num_frames = 50;
    options.step = 0.06;
    return ::vmap::testing::RenderSyntheticSequence(options);
  }();
  return sequence;
}

cv::Mat Gray(int frame) {
  cv::Mat gray;
  cv::cvtColor(Drive().frames[frame], gray, cv::COLOR_BGR2GRAY);
  return gray;
}

// Features without per-feature descriptors (as LoFTR's), or with the given ones.
class PlainFeatures : public ImageFeatures {
 public:
  explicit PlainFeatures(cv::Mat descriptors = {}) : descriptors_(std::move(descriptors)) {}
  int num_features() const override { return descriptors_.rows; }
  cv::Size image_size() const override { return {320, 240}; }
  cv::Mat descriptors() const override { return descriptors_; }

 private:
  cv::Mat descriptors_;
};

struct Keys {
  std::vector<int> frames = {0, 10, 20, 30, 40};
  std::vector<std::shared_ptr<const ImageFeatures>> features;
  std::vector<cv::Mat> thumbnails;
};

const Keys& OrbKeys() {
  static const Keys keys = [] {
    Keys k;
    const auto matcher = CreateOrbMatcher({});
    for (int f : k.frames) {
      k.features.push_back(matcher->Extract(Gray(f)));
      k.thumbnails.push_back(ThumbnailDescriptor(Gray(f), 48));
    }
    return k;
  }();
  return keys;
}

TEST(Thumbnail, IsZeroMeanUnitNormAndIgnoresBrightnessAndContrast) {
  const cv::Mat gray = Gray(5);
  const cv::Mat t = ThumbnailDescriptor(gray, 48);
  EXPECT_EQ(t.type(), CV_32F);
  EXPECT_EQ(t.rows, 1);
  EXPECT_EQ(t.cols, 48 * 36);  // 320x240 keeps its aspect
  EXPECT_NEAR(cv::norm(t), 1.0, 1e-5);
  EXPECT_NEAR(cv::mean(t)[0], 0.0, 1e-6);
  cv::Mat changed;
  gray.convertTo(changed, CV_8U, 0.7, 30);
  EXPECT_GT(t.dot(ThumbnailDescriptor(changed, 48)), 0.99);
  EXPECT_LT(t.dot(ThumbnailDescriptor(Gray(45), 48)), 0.9);
  // A flat image correlates with nothing.
  EXPECT_EQ(cv::norm(ThumbnailDescriptor(cv::Mat(240, 320, CV_8U, cv::Scalar(90)), 48)), 0.0);
}

TEST(KeyImageRanking, BothRankingsPutTheNearestKeyImageFirst) {
  const Keys& keys = OrbKeys();
  const auto matcher = CreateOrbMatcher({});
  for (RankingMethod method : {RankingMethod::kVotes, RankingMethod::kThumbnails}) {
    RankingOptions options;
    options.method = method;
    const KeyImageRanking ranking(keys.features, keys.thumbnails, options);
    EXPECT_EQ(ranking.method(), method);
    for (auto [frame, expected] : std::vector<std::pair<int, int>>{{1, 0}, {21, 2}, {29, 3}, {41, 4}}) {
      const auto ranked = ranking.Rank(*matcher->Extract(Gray(frame)), ThumbnailDescriptor(Gray(frame), 48));
      ASSERT_EQ(ranked.size(), keys.frames.size());
      EXPECT_EQ(ranked[0].key, expected) << RankingMethodName(method) << ", frame " << frame;
      for (size_t i = 1; i < ranked.size(); ++i) EXPECT_GE(ranked[i - 1].score, ranked[i].score);
    }
  }
}

TEST(KeyImageRanking, AutoVotesWithDescriptorsAndUsesThumbnailsWithout) {
  const Keys& keys = OrbKeys();
  EXPECT_EQ(KeyImageRanking(keys.features, keys.thumbnails, {}).method(), RankingMethod::kVotes);
  std::vector<std::shared_ptr<const ImageFeatures>> plain(keys.features.size(), std::make_shared<PlainFeatures>());
  EXPECT_EQ(KeyImageRanking(plain, keys.thumbnails, {}).method(), RankingMethod::kThumbnails);
  RankingOptions votes;
  votes.method = RankingMethod::kVotes;
  EXPECT_THROW(KeyImageRanking(plain, keys.thumbnails, votes), InputError);
}

TEST(KeyImageRanking, FloatDescriptorsVoteByCosine) {
  // Five key images with random unit descriptors; the query sees key image 3's features, slightly changed.
  cv::RNG rng(11);
  std::vector<std::shared_ptr<const ImageFeatures>> features;
  std::vector<cv::Mat> thumbnails;
  std::vector<cv::Mat> descriptors;
  for (int k = 0; k < 5; ++k) {
    cv::Mat d(300, 64, CV_32F);
    rng.fill(d, cv::RNG::NORMAL, 0, 1);
    for (int r = 0; r < d.rows; ++r) cv::normalize(d.row(r), d.row(r));
    descriptors.push_back(d);
    features.push_back(std::make_shared<PlainFeatures>(d));
    thumbnails.push_back(cv::Mat::zeros(1, 48 * 36, CV_32F));
  }
  cv::Mat query = descriptors[3].rowRange(0, 200).clone(), noise(query.size(), CV_32F);
  rng.fill(noise, cv::RNG::NORMAL, 0, 0.05);
  query += noise;
  for (int r = 0; r < query.rows; ++r) cv::normalize(query.row(r), query.row(r));
  const KeyImageRanking ranking(features, thumbnails, {});
  EXPECT_EQ(ranking.method(), RankingMethod::kVotes);
  const auto ranked = ranking.Rank(PlainFeatures(query), cv::Mat());
  EXPECT_EQ(ranked[0].key, 3);
  EXPECT_GE(ranked[0].score, 150.0);
  EXPECT_LT(ranked[1].score, 10.0);
}

TEST(KeyImageRanking, OptionsAreChecked) {
  auto bad = [](auto change) {
    RankingOptions o;
    change(o);
    return o;
  };
  EXPECT_THROW(bad([](RankingOptions& o) { o.max_hamming_fraction = 0.0; }).Check(), InputError);
  EXPECT_THROW(bad([](RankingOptions& o) { o.min_cosine = 1.0; }).Check(), InputError);
  EXPECT_THROW(bad([](RankingOptions& o) { o.max_descriptors_per_key = -1; }).Check(), InputError);
  EXPECT_THROW(bad([](RankingOptions& o) { o.thumbnail_width = 4; }).Check(), InputError);
  EXPECT_THROW(ParseRankingMethod("bow"), InputError);
  EXPECT_EQ(ParseRankingMethod(RankingMethodName(RankingMethod::kThumbnails)), RankingMethod::kThumbnails);
}

}  // namespace
}  // namespace vmap
