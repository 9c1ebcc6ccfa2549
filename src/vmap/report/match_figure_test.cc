#include "vmap/report/match_figure.h"

#include <stdexcept>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "vmap/core/error.h"

namespace vmap {
namespace {

bool IsGreen(const cv::Vec3b& bgr) { return bgr[1] > 120 && bgr[0] < 90 && bgr[2] < 90; }
bool IsBlue(const cv::Vec3b& bgr) { return bgr[0] > 150 && bgr[1] < 120 && bgr[2] < 60; }
bool IsRed(const cv::Vec3b& bgr) { return bgr[2] > 150 && bgr[0] < 60 && bgr[1] < 60; }

// One verified match joining (40, 50) to (40, 50) and one rejected match, on black images.
Link SimpleLink() {
  Link link;
  link.from_key = 0;
  link.to_key = 1;
  link.correspondences = {{{40.f, 50.f}, {40.f, 50.f}}, {{150.f, 20.f}, {170.f, 80.f}}};
  link.num_verified = 1;
  link.num_tentative = 2;
  link.similarity = 0.5;
  return link;
}

TEST(MatchFigureTest, PutsImagesSideBySideWithGreenLinesAndBluePoints) {
  const cv::Mat black(100, 200, CV_8UC3, cv::Scalar::all(0));
  const cv::Mat figure = DrawMatchFigure(black, black, SimpleLink(), {});
  ASSERT_EQ(figure.type(), CV_8UC3);
  EXPECT_GE(figure.cols, 404);
  EXPECT_LE(figure.cols, 420);
  EXPECT_GT(figure.rows, 100);           // the caption band
  const int offset = figure.cols - 200;  // where the second image starts
  // The green line runs at y = 50 from the first image into the second.
  EXPECT_TRUE(IsGreen(figure.at<cv::Vec3b>(50, 120)));
  EXPECT_TRUE(IsGreen(figure.at<cv::Vec3b>(50, offset + 20)));
  EXPECT_FALSE(IsGreen(figure.at<cv::Vec3b>(70, 120)));
  // The rejected match is a blue point in each image and nothing between them.
  EXPECT_TRUE(IsBlue(figure.at<cv::Vec3b>(20, 150)));
  EXPECT_TRUE(IsBlue(figure.at<cv::Vec3b>(80, offset + 170)));
  EXPECT_FALSE(IsBlue(figure.at<cv::Vec3b>(50, 160)));
}

TEST(MatchFigureTest, LinkBelowTauGetsARedBorderAndCaption) {
  const cv::Mat grey(100, 200, CV_8UC3, cv::Scalar::all(128));
  Link link = SimpleLink();
  const cv::Mat normal = DrawMatchFigure(grey, grey, link, {});
  link.below_tau = true;
  const cv::Mat below_tau = DrawMatchFigure(grey, grey, link, {});
  EXPECT_FALSE(IsRed(normal.at<cv::Vec3b>(0, 0)));
  EXPECT_TRUE(IsRed(below_tau.at<cv::Vec3b>(0, 0)));
  EXPECT_TRUE(IsRed(below_tau.at<cv::Vec3b>(below_tau.rows / 3, below_tau.cols - 1)));
  // The caption band (bottom left corner, left of the text) is red only for the link below tau.
  EXPECT_TRUE(IsRed(below_tau.at<cv::Vec3b>(below_tau.rows - 2, 2)));
  EXPECT_FALSE(IsRed(normal.at<cv::Vec3b>(normal.rows - 2, 2)));
}

TEST(MatchFigureTest, ScalesDownToMaxWidthAndKeepsPointsOnTheImages) {
  const cv::Mat black(480, 640, CV_8UC3, cv::Scalar::all(0));
  Link link;
  link.correspondences = {{{320.f, 240.f}, {320.f, 240.f}}};
  link.num_verified = link.num_tentative = 1;
  MatchFigureOptions options;
  options.max_width = 480;
  const cv::Mat figure = DrawMatchFigure(black, black, link, options);
  EXPECT_LE(figure.cols, 480);
  EXPECT_GE(figure.cols, 470);
  // Both images scale by about 480 / 1286: the line runs at y = 240 * 0.37, from x = 320 * 0.37.
  const double s = 480.0 / (2 * 640 + 6);
  EXPECT_TRUE(IsGreen(figure.at<cv::Vec3b>(static_cast<int>(240 * s), static_cast<int>(320 * s) + 30)));
}

TEST(MatchFigureTest, AcceptsGreyImagesOfDifferentSizes) {
  const cv::Mat small(50, 100, CV_8UC1, cv::Scalar(0));
  const cv::Mat large(100, 200, CV_8UC3, cv::Scalar::all(0));
  Link link;
  link.correspondences = {{{10.f, 25.f}, {20.f, 50.f}}};
  link.num_verified = link.num_tentative = 1;
  MatchFigureOptions options;
  options.caption = false;
  const cv::Mat figure = DrawMatchFigure(small, large, link, options);
  EXPECT_EQ(figure.rows, 100);  // both at the taller height, no caption
  EXPECT_EQ(figure.type(), CV_8UC3);
  // The small image doubles: its point (10, 25) lands at about (20.5, 50.5).
  EXPECT_TRUE(IsGreen(figure.at<cv::Vec3b>(50, 21)));
}

TEST(MatchFigureTest, RejectsEmptyImages) {
  EXPECT_THROW(DrawMatchFigure(cv::Mat(), cv::Mat(10, 10, CV_8UC3), SimpleLink()), std::invalid_argument);
}

TEST(MatchFigureTest, BadOptionsNameTheField) {
  MatchFigureOptions options;
  EXPECT_NO_THROW(options.Check());
  options.max_width = 64;
  EXPECT_NO_THROW(options.Check());
  for (int width : {-1, 63, 16385}) {
    options.max_width = width;
    try {
      DrawMatchFigure(cv::Mat(10, 10, CV_8UC3), cv::Mat(10, 10, CV_8UC3), SimpleLink(), options);
      ADD_FAILURE() << "max_width " << width << " accepted";
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find("max_width is " + std::to_string(width)), std::string::npos)
          << error.what();
    }
  }
}

TEST(MatchFigureTest, CaptionGivesSimilarityAndCounts) {
  Link link = SimpleLink();
  link.similarity = 0.4123;
  link.num_verified = 1;
  link.num_tentative = 5;
  EXPECT_EQ(MatchCaption(link), "S = 0.412 | 1 verified (green), 4 rejected (blue) of 5 tentative");
}

}  // namespace
}  // namespace vmap
