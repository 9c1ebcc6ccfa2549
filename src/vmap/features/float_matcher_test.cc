#include "vmap/features/float_matcher.h"

#include <random>
#include <thread>

#include <gtest/gtest.h>

namespace vmap {
namespace {

cv::Mat RandomUnitRows(int rows, int cols, std::mt19937& random) {
  std::normal_distribution<float> normal;
  cv::Mat m(rows, cols, CV_32F);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) m.at<float>(r, c) = normal(random);
    cv::normalize(m.row(r), m.row(r));
  }
  return m;
}

// The definition, written plainly: full similarity matrix, argmax both ways (first index on ties).
std::vector<FloatMatch> PlainMutualNearest(const cv::Mat& q, const cv::Mat& t, float min_similarity) {
  cv::Mat s = q * t.t();
  std::vector<FloatMatch> out;
  for (int i = 0; i < q.rows; ++i) {
    int best_j = 0;
    for (int j = 1; j < t.rows; ++j)
      if (s.at<float>(i, j) > s.at<float>(i, best_j)) best_j = j;
    int best_i = 0;
    for (int k = 1; k < q.rows; ++k)
      if (s.at<float>(k, best_j) > s.at<float>(best_i, best_j)) best_i = k;
    if (best_i == i && s.at<float>(i, best_j) >= min_similarity) out.push_back({i, best_j, s.at<float>(i, best_j)});
  }
  return out;
}

TEST(MatchFloatDescriptors, FindsPermutedNoisyCopies) {
  std::mt19937 random(3);
  const cv::Mat train = RandomUnitRows(700, 64, random);
  // Query = rows of train in another order, with a little noise, plus unrelated rows.
  std::vector<int> order(train.rows);
  for (int i = 0; i < train.rows; ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), random);
  cv::Mat query(600, 64, CV_32F);
  cv::Mat noise = RandomUnitRows(600, 64, random);
  for (int i = 0; i < 500; ++i) {
    cv::Mat row = train.row(order[i]) + 0.05f * noise.row(i);
    cv::normalize(row, query.row(i));
  }
  RandomUnitRows(100, 64, random).copyTo(query.rowRange(500, 600));

  const std::vector<FloatMatch> matches = MatchFloatDescriptors(query, train, 0.9f);
  ASSERT_EQ(matches.size(), 500u);  // the unrelated rows stay below 0.9 (random 64-d unit vectors: |cos| ~ 0.12)
  for (const FloatMatch& m : matches) {
    ASSERT_LT(m.query, 500);
    EXPECT_EQ(m.train, order[m.query]);
    EXPECT_GE(m.similarity, 0.9f);
  }
}

TEST(MatchFloatDescriptors, AgreesWithThePlainDefinitionAcrossBlocksAndThresholds) {
  std::mt19937 random(7);
  // Row counts around the product sizes (at least 128 rows, 256 at a time) and train sets of one and of
  // several 1024-column tiles.
  for (const auto& [rows, train_rows] : std::vector<std::pair<int, int>>{{1, 300},
                                                                         {127, 2100},
                                                                         {128, 300},
                                                                         {255, 300},
                                                                         {256, 2100},
                                                                         {257, 300},
                                                                         {383, 300},
                                                                         {384, 1100},
                                                                         {600, 300}}) {
    const cv::Mat q = RandomUnitRows(rows, 32, random);
    const cv::Mat t = RandomUnitRows(train_rows, 32, random);
    for (float threshold : {-1.f, 0.3f, 0.5f}) {
      const auto expected = PlainMutualNearest(q, t, threshold);
      const auto got = MatchFloatDescriptors(q, t, threshold);
      ASSERT_EQ(got.size(), expected.size()) << rows << " x " << train_rows << " rows, threshold " << threshold;
      for (size_t k = 0; k < got.size(); ++k) {
        EXPECT_EQ(got[k].query, expected[k].query);
        EXPECT_EQ(got[k].train, expected[k].train);
        EXPECT_NEAR(got[k].similarity, expected[k].similarity, 1e-5f);
      }
    }
  }
}

// Descriptors like a network's: most of their spread on a few axes, the rest small but not negligible.
cv::Mat AnisotropicRows(int rows, int cols, std::mt19937& random) {
  cv::Mat m = RandomUnitRows(rows, cols, random);
  for (int c = 0; c < cols; ++c) m.col(c) *= 1.0 / (1.0 + 0.15 * c);
  for (int r = 0; r < rows; ++r) cv::normalize(m.row(r), m.row(r));
  return m;
}

// The fast path (a high floor, wide descriptors, at least 128 x 1024 rows) rules most pairs out by a bound
// on a projection; it must never rule out a pair at or above the floor. Noisy copies put similarities on
// both sides of every floor; rows of other lengths than 1 and repeated train rows (ties) are included.
TEST(MatchFloatDescriptors, TheBoundOnAProjectionNeverLosesAMatch) {
  std::mt19937 random(11);
  const cv::Mat train = AnisotropicRows(2100, 64, random);
  train.row(7).copyTo(train.row(1500));  // a tie: query rows near row 7 must pick 7
  train.row(40) *= 1.3;
  cv::Mat query(1300, 64, CV_32F);
  const cv::Mat noise = AnisotropicRows(query.rows, 64, random);
  std::uniform_int_distribution<int> any_train(0, train.rows - 1);
  std::uniform_real_distribution<float> amount(0.f, 0.9f);
  for (int i = 0; i < query.rows; ++i) {
    cv::Mat row = train.row(i < 10 ? 7 : any_train(random)) + amount(random) * noise.row(i);
    cv::normalize(row, query.row(i));
  }
  query.row(3) *= 0.8;
  for (float floor : {0.5f, 0.7f, 0.82f, 0.9f}) {
    const auto expected = PlainMutualNearest(query, train, floor);
    const auto got = MatchFloatDescriptors(query, train, floor);
    ASSERT_GT(expected.size(), 100u) << floor;
    ASSERT_EQ(got.size(), expected.size()) << "floor " << floor;
    for (size_t k = 0; k < got.size(); ++k) {
      EXPECT_EQ(got[k].query, expected[k].query) << floor;
      EXPECT_EQ(got[k].train, expected[k].train) << floor;
      EXPECT_NEAR(got[k].similarity, expected[k].similarity, 1e-5f);
    }
    const auto exhaustive = MatchFloatDescriptorsExhaustively(query, train, floor);
    EXPECT_EQ(exhaustive.size(), expected.size()) << floor;
  }
}

// A key image's rows keep the bound's train side between frames: every frame, floor and thread gets the
// matches of a bound computed afresh, including threads that race to compute it first.
TEST(MatchFloatDescriptors, TrainRowsKeepTheirBoundAndGiveTheSameMatches) {
  std::mt19937 random(5);
  const cv::Mat train_rows = AnisotropicRows(1500, 64, random);
  std::vector<cv::Mat> queries;
  for (int q = 0; q < 4; ++q) {
    cv::Mat query(400, 64, CV_32F);
    const cv::Mat noise = AnisotropicRows(query.rows, 64, random);
    std::uniform_int_distribution<int> any_train(0, train_rows.rows - 1);
    for (int i = 0; i < query.rows; ++i) {
      cv::Mat row = train_rows.row(any_train(random)) + (0.1f * q + 0.1f) * noise.row(i);
      cv::normalize(row, query.row(i));
    }
    queries.push_back(query);
  }
  auto same = [](const std::vector<FloatMatch>& a, const std::vector<FloatMatch>& b) {
    if (a.size() != b.size()) return false;
    for (size_t k = 0; k < a.size(); ++k) {
      if (a[k].query != b[k].query || a[k].train != b[k].train || a[k].similarity != b[k].similarity) return false;
    }
    return true;
  };
  const FloatTrainRows train(train_rows);
  std::vector<int> agreed(8, 0);
  std::vector<std::thread> threads;
  for (int t = 0; t < 8; ++t) {
    threads.emplace_back([&, t] {
      for (float floor : {0.82f, 0.6f, 0.3f}) {
        const cv::Mat& query = queries[t % queries.size()];
        agreed[t] += same(MatchFloatDescriptors(query, train, floor), MatchFloatDescriptors(query, train_rows, floor));
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  for (int t = 0; t < 8; ++t) EXPECT_EQ(agreed[t], 3) << "thread " << t;
  const auto matches = MatchFloatDescriptors(queries[0], train, 0.82f);
  const auto expected = PlainMutualNearest(queries[0], train_rows, 0.82f);
  EXPECT_GT(expected.size(), 200u);
  ASSERT_EQ(matches.size(), expected.size());
  for (size_t k = 0; k < matches.size(); ++k) {
    EXPECT_EQ(matches[k].query, expected[k].query);
    EXPECT_EQ(matches[k].train, expected[k].train);
  }
  EXPECT_EQ(train.rows().data, train_rows.data);  // a header, not a copy
}

TEST(MatchFloatDescriptors, TiesGoToTheLowestIndexAndEmptyInputsGiveNothing) {
  cv::Mat q = (cv::Mat_<float>(2, 2) << 1, 0, 1, 0);  // two identical query rows
  cv::Mat t = (cv::Mat_<float>(3, 2) << 0, 1, 1, 0, 1, 0);
  const auto matches = MatchFloatDescriptors(q, t, 0.5f);
  ASSERT_EQ(matches.size(), 1u);
  EXPECT_EQ(matches[0].query, 0);
  EXPECT_EQ(matches[0].train, 1);
  EXPECT_TRUE(MatchFloatDescriptors(cv::Mat(), t, 0.f).empty());
  EXPECT_TRUE(MatchFloatDescriptors(q, cv::Mat(0, 2, CV_32F), 0.f).empty());
}

}  // namespace
}  // namespace vmap
