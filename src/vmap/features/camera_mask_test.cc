#include "vmap/features/camera_mask.h"

#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "vmap/core/error.h"
#include "vmap/features/matcher_registry.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/testing/localization_test_util.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace {
namespace fs = std::filesystem;

// Black on the left half: no features there.
cv::Mat LeftHalfMasked(cv::Size size) {
  cv::Mat mask(size, CV_8UC1, cv::Scalar(200));
  mask.colRange(0, size.width / 2).setTo(0);
  return mask;
}

std::string ReadError(const fs::path& file) {
  try {
    CameraMask::Read(file);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(CameraMask, KeepsWhatIsNotBlackAndRefusesWhatIsNoMask) {
  testing::ScopedTempDir tmp;
  cv::imwrite((tmp.path() / "mask.png").string(), LeftHalfMasked({64, 48}));
  const CameraMask mask = CameraMask::Read(tmp.path() / "mask.png");
  EXPECT_DOUBLE_EQ(mask.kept_share(), 0.5);
  EXPECT_EQ(mask.image().at<uchar>(10, 40), 255);
  EXPECT_EQ(mask.image().at<uchar>(10, 10), 0);

  EXPECT_NE(ReadError(tmp.path() / "none.png").find("camera mask '" + (tmp.path() / "none.png").string()),
            std::string::npos);
  std::ofstream(tmp.path() / "text.png") << "not an image";
  EXPECT_NE(ReadError(tmp.path() / "text.png").find("cannot be decoded (corrupt or not an image)"), std::string::npos);
  cv::imwrite((tmp.path() / "black.png").string(), cv::Mat(48, 64, CV_8UC1, cv::Scalar(0)));
  EXPECT_NE(ReadError(tmp.path() / "black.png").find("is black everywhere"), std::string::npos);
  EXPECT_NE(ReadError(tmp.path()).find("is not a regular file"), std::string::npos) << ReadError(tmp.path());
}

TEST(CameraMask, FollowsTheImagesSizeOnlyAtItsAspectRatio) {
  const CameraMask mask(LeftHalfMasked({64, 48}), "the test's mask");
  EXPECT_EQ(mask.For({64, 48}).data, mask.image().data);
  const cv::Mat half = mask.For({32, 24});
  ASSERT_EQ(half.size(), cv::Size(32, 24));
  EXPECT_EQ(cv::countNonZero(half), 16 * 24);
  EXPECT_EQ(mask.For({65, 49}).size(), cv::Size(65, 49));  // a size --resize rounds
  try {
    mask.For({64, 64});
    FAIL() << "another aspect ratio was taken";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("the test's mask is 64x48, the images are 64x64"), std::string::npos)
        << error.what();
  }
}

// ORB's detector looks within the mask: every feature on the kept half, and about as many as without a mask
// (the best num_features are found there, not the best of the image less those outside).
TEST(CameraMask, OrbFindsItsFeaturesWithinTheMask) {
  cv::Mat image, next;
  cv::cvtColor(testing::SidewaysDrive().frames.at(0), image, cv::COLOR_BGR2GRAY);
  cv::cvtColor(testing::SidewaysDrive().frames.at(2), next, cv::COLOR_BGR2GRAY);
  MatcherOptions options;
  options.Of<OrbMatcherOptions>().num_features = 300;
  const std::unique_ptr<Matcher> plain = CreateMatcher(options);
  const std::unique_ptr<Matcher> masked =
      WithCameraMask(CreateMatcher(options), CameraMask(LeftHalfMasked(image.size()), "mask"));
  EXPECT_EQ(masked->name(), "orb");

  const auto plain_features = plain->Extract(image);
  const auto masked_features = masked->Extract(image);
  const TentativeMatches everywhere = plain->Match(*plain_features, *plain->Extract(next));
  const TentativeMatches within = masked->Match(*masked_features, *masked->Extract(next));
  ASSERT_GT(within.size(), 20u);
  const float middle = image.cols / 2.f;
  int left_everywhere = 0;
  for (const cv::Point2f& p : everywhere.points0) left_everywhere += p.x < middle - 1.f;
  EXPECT_GT(left_everywhere, 20);  // the scene has features there
  for (size_t i = 0; i < within.size(); ++i) {
    EXPECT_GE(within.points0[i].x, middle - 0.5f);
    EXPECT_GE(within.points1[i].x, middle - 0.5f);
  }
  EXPECT_GE(masked_features->num_features(), plain_features->num_features() * 9 / 10);
}

// A masked matcher within another mask keeps features where both keep pixels, and neither mask is changed by it.
TEST(CameraMask, TwoMasksKeepWhereBothKeep) {
  cv::Mat image, next;
  cv::cvtColor(testing::SidewaysDrive().frames.at(0), image, cv::COLOR_BGR2GRAY);
  cv::cvtColor(testing::SidewaysDrive().frames.at(2), next, cv::COLOR_BGR2GRAY);
  cv::Mat top_masked(image.size(), CV_8UC1, cv::Scalar(255));
  top_masked.rowRange(0, image.rows / 2).setTo(0);
  // A mask's copies share its pixels (cv::Mat): were a matcher to write into them, `left` would show it.
  const CameraMask left(LeftHalfMasked(image.size()), "left");
  const auto inner = WithCameraMask(CreateMatcher(MatcherOptions()), left);
  const auto both =
      WithCameraMask(WithCameraMask(CreateMatcher(MatcherOptions()), left), CameraMask(top_masked, "top"));
  const TentativeMatches matches = both->Match(*both->Extract(image), *both->Extract(next));
  ASSERT_GT(matches.size(), 10u);
  for (const cv::Point2f& p : matches.points0) {
    EXPECT_GE(p.x, image.cols / 2 - 0.5f);
    EXPECT_GE(p.y, image.rows / 2 - 0.5f);
  }
  EXPECT_EQ(cv::countNonZero(left.image()), static_cast<int>(image.total() / 2));
  const TentativeMatches inner_matches = inner->Match(*inner->Extract(image), *inner->Extract(next));
  int top = 0;
  for (const cv::Point2f& p : inner_matches.points0) top += p.y < image.rows / 2 - 1;
  EXPECT_GT(top, 10);  // the left mask alone keeps the top half
}

// A matcher that cannot leave features out: its matches with an end outside the mask are dropped.
class EveryPixelMatcher : public Matcher {
 public:
  class Features : public ImageFeatures {
   public:
    explicit Features(cv::Size size) : size_(size) {}
    int num_features() const override { return size_.area(); }
    cv::Size image_size() const override { return size_; }

   private:
    cv::Size size_;
  };
  std::string name() const override { return "every-pixel"; }
  std::shared_ptr<const ImageFeatures> Extract(const cv::Mat& gray) const override {
    return std::make_shared<Features>(gray.size());
  }
  TentativeMatches Match(const ImageFeatures& a, const ImageFeatures&) const override {
    TentativeMatches matches;
    for (int y = 0; y < a.image_size().height; y += 4) {
      for (int x = 0; x < a.image_size().width; x += 4) {
        matches.points0.emplace_back(float(x), float(y));
        matches.points1.emplace_back(float(a.image_size().width - 1 - x), float(y));  // mirrored
        matches.scores.push_back(float(x));
      }
    }
    return matches;
  }
  std::string DescribeOptionsJson() const override { return R"({"type": "every-pixel"})"; }
};

TEST(CameraMask, MatchesOfAMatcherThatExtractsEverywhereAreFiltered) {
  const cv::Size size(64, 48);
  const auto masked = WithCameraMask(std::make_unique<EveryPixelMatcher>(), CameraMask(LeftHalfMasked(size), "mask"));
  const cv::Mat image(size, CV_8UC1, cv::Scalar(0));
  const TentativeMatches all =
      EveryPixelMatcher().Match(EveryPixelMatcher::Features(size), EveryPixelMatcher::Features(size));
  const TentativeMatches kept = masked->Match(*masked->Extract(image), *masked->Extract(image));
  ASSERT_GT(all.size(), 0u);
  // Mirrored: an end is outside the mask for every match, so none is left.
  EXPECT_EQ(kept.size(), 0u);

  // Masking the top rows instead keeps the bottom ones, scores along.
  cv::Mat top(size, CV_8UC1, cv::Scalar(255));
  top.rowRange(0, 24).setTo(0);
  const auto bottom_only = WithCameraMask(std::make_unique<EveryPixelMatcher>(), CameraMask(top, "top"));
  const TentativeMatches bottom = bottom_only->Match(*bottom_only->Extract(image), *bottom_only->Extract(image));
  EXPECT_EQ(bottom.size(), all.size() / 2);
  ASSERT_EQ(bottom.scores.size(), bottom.size());
  for (const cv::Point2f& p : bottom.points0) EXPECT_GE(p.y, 24.f);
}

TEST(CameraMask, TheMatchersRecordNamesItsMask) {
  const cv::Size size(64, 48);
  const auto masked = WithCameraMask(std::make_unique<EveryPixelMatcher>(), CameraMask(LeftHalfMasked(size), "mask"));
  const nlohmann::json record = nlohmann::json::parse(masked->DescribeOptionsJson());
  EXPECT_EQ(record.at("type"), "every-pixel");
  const std::string described = record.at("camera_mask");
  EXPECT_EQ(described.rfind("64x48 50.0% ", 0), 0u) << described;
  cv::Mat other = LeftHalfMasked(size);
  other.at<uchar>(0, 0) = 255;
  EXPECT_NE(CameraMask(other, "other").Describe(), described);  // another mask, another record: caches are not reused

  ASSERT_NE(CameraMaskOf(*masked), nullptr);
  EXPECT_EQ(CameraMaskOf(EveryPixelMatcher()), nullptr);
  const auto like = WithCameraMaskOf(*masked, std::make_unique<EveryPixelMatcher>());
  ASSERT_NE(CameraMaskOf(*like), nullptr);
  EXPECT_EQ(CameraMaskOf(*like)->Describe(), described);
  EXPECT_EQ(CameraMaskOf(*WithCameraMaskOf(EveryPixelMatcher(), std::make_unique<EveryPixelMatcher>())), nullptr);
}

TEST(CameraMask, CreateMatcherReadsTheOptionsMask) {
  testing::ScopedTempDir tmp;
  cv::imwrite((tmp.path() / "mask.png").string(), LeftHalfMasked({64, 48}));
  MatcherOptions options;
  options.camera_mask = (tmp.path() / "mask.png").string();
  const std::unique_ptr<Matcher> matcher = CreateMatcher(options);
  ASSERT_NE(CameraMaskOf(*matcher), nullptr);
  EXPECT_DOUBLE_EQ(CameraMaskOf(*matcher)->kept_share(), 0.5);
  const MatcherOptions copy = options;
  EXPECT_EQ(copy.camera_mask, options.camera_mask);
  options.camera_mask = (tmp.path() / "missing.png").string();
  EXPECT_THROW(CreateMatcher(options), InputError);
}

}  // namespace
}  // namespace vmap
