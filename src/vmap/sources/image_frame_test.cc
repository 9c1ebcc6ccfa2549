#include "vmap/sources/image_frame.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "vmap/core/error.h"

namespace vmap {

TEST(FrameFromImage, GreyFromBgrAndBroughtToTheSizeAsked) {
  cv::Mat bgr(240, 320, CV_8UC3);
  cv::randu(bgr, cv::Scalar::all(0), cv::Scalar::all(255));
  const Frame frame = FrameFromImage(bgr, 7);
  EXPECT_EQ(frame.index, 7);
  EXPECT_EQ(frame.source_name, "frame_000007");
  cv::Mat expected;
  cv::cvtColor(bgr, expected, cv::COLOR_BGR2GRAY);
  EXPECT_EQ(cv::norm(frame.gray, expected, cv::NORM_INF), 0.0);
  EXPECT_FALSE(frame.resized);

  const Frame smaller = FrameFromImage(bgr, 0, cv::Size(160, 120));
  EXPECT_EQ(smaller.gray.size(), cv::Size(160, 120));
  EXPECT_EQ(smaller.color.size(), cv::Size(160, 120));
  EXPECT_TRUE(smaller.resized);

  // A grey image is taken as it is (a copy: the caller's buffer may change afterwards).
  const Frame grey = FrameFromImage(expected, 0);
  EXPECT_EQ(cv::norm(grey.gray, expected, cv::NORM_INF), 0.0);
  EXPECT_NE(grey.gray.data, expected.data);
}

TEST(FrameFromImage, RefusesImagesNoSourceWouldDeliver) {
  for (const cv::Mat& bad : {cv::Mat(240, 320, CV_32F, cv::Scalar(0)), cv::Mat(240, 320, CV_8UC2, cv::Scalar(0)),
                             cv::Mat(4, 4, CV_8U, cv::Scalar(0))}) {
    try {
      FrameFromImage(bad, 0, {}, "image0");
      ADD_FAILURE() << "accepted type " << bad.type() << ", " << bad.cols << "x" << bad.rows;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("image0"), std::string::npos) << e.what();
    }
  }
}

}  // namespace vmap
