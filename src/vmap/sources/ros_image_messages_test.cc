#include "vmap/sources/ros_image_messages.h"

#include <array>
#include <map>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "vmap/core/error.h"
#include "vmap/testing/recording_writer.h"

namespace vmap {
namespace {

constexpr MessageEncoding kEncodings[] = {MessageEncoding::kRos1, MessageEncoding::kCdr};

// A smooth colour image whose three channels differ everywhere, so that a swapped channel or a wrong Bayer
// pattern shows.
cv::Mat TestImage() {
  cv::Mat bgr(48, 64, CV_8UC3);
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; ++x) bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(30 + x / 2, 90 + y, 220 - x / 3);
  }
  return bgr;
}

DecodedImage Decode(const std::vector<uint8_t>& data, MessageEncoding encoding, const char* type = kImageType) {
  return DecodeImageMessage(data.data(), data.size(), type, encoding, "test message");
}

double MeanDifference(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat difference;
  cv::absdiff(a, b, difference);
  return cv::mean(difference.reshape(1))[0];
}

TEST(RosImageMessages, ColourEncodingsGiveTheSameBgrImageAndStamp) {
  const cv::Mat bgr = TestImage();
  cv::Mat rgb, bgra, rgba, gray;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  cv::cvtColor(bgr, bgra, cv::COLOR_BGR2BGRA);
  cv::cvtColor(bgr, rgba, cv::COLOR_BGR2RGBA);
  cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
  for (MessageEncoding encoding : kEncodings) {
    for (const auto& [name, pixels] :
         {std::pair<const char*, cv::Mat>{"bgr8", bgr}, {"rgb8", rgb}, {"bgra8", bgra}, {"rgba8", rgba}}) {
      SCOPED_TRACE(name);
      // frame_id lengths that leave CDR's uint32 fields unaligned unless padded, and rows with padding.
      const DecodedImage image =
          Decode(testing::SerializeImage(encoding, 12.25, "cam_0", pixels, name, /*padding=*/3), encoding);
      EXPECT_DOUBLE_EQ(image.stamp, 12.25);
      EXPECT_EQ(MeanDifference(image.color, bgr), 0.0);
      EXPECT_EQ(MeanDifference(image.gray, gray), 0.0);
    }
  }
}

TEST(RosImageMessages, MonoEncodings) {
  cv::Mat gray;
  cv::cvtColor(TestImage(), gray, cv::COLOR_BGR2GRAY);
  cv::Mat wide;
  gray.convertTo(wide, CV_16U, 256.0);
  for (MessageEncoding encoding : kEncodings) {
    const DecodedImage mono8 = Decode(testing::SerializeImage(encoding, 1.0, "c", gray, "mono8"), encoding);
    EXPECT_TRUE(mono8.color.empty());
    EXPECT_EQ(MeanDifference(mono8.gray, gray), 0.0);
    const DecodedImage mono16 = Decode(testing::SerializeImage(encoding, 1.0, "c", wide, "mono16", 2), encoding);
    EXPECT_EQ(MeanDifference(mono16.gray, gray), 0.0);
  }
}

// Each ROS Bayer pattern names the colour of the top-left 2x2 block's pixels; mosaicking the test image in that
// pattern and decoding it must give the image back, up to demosaicing's interpolation (a wrong pattern swaps
// red and blue, which differ by over 100 here).
TEST(RosImageMessages, BayerPatternsDemosaicToTheImage) {
  const cv::Mat bgr = TestImage();
  const std::map<std::string, std::array<int, 4>> patterns = {// channel (B 0, G 1, R 2) at (0,0) (0,1) (1,0) (1,1)
                                                              {"bayer_rggb8", {2, 1, 1, 0}},
                                                              {"bayer_bggr8", {0, 1, 1, 2}},
                                                              {"bayer_gbrg8", {1, 0, 2, 1}},
                                                              {"bayer_grbg8", {1, 2, 0, 1}}};
  for (const auto& [name, channels] : patterns) {
    SCOPED_TRACE(name);
    cv::Mat mosaic(bgr.size(), CV_8UC1);
    for (int y = 0; y < bgr.rows; ++y) {
      for (int x = 0; x < bgr.cols; ++x) {
        mosaic.at<uint8_t>(y, x) = bgr.at<cv::Vec3b>(y, x)[channels[(y % 2) * 2 + x % 2]];
      }
    }
    for (MessageEncoding encoding : kEncodings) {
      const DecodedImage image = Decode(testing::SerializeImage(encoding, 1.0, "c", mosaic, name), encoding);
      EXPECT_LT(MeanDifference(image.color, bgr), 3.0);
    }
  }
}

TEST(RosImageMessages, CompressedJpegAndPng) {
  const cv::Mat bgr = TestImage();
  for (const char* format : {".png", ".jpg"}) {
    std::vector<uint8_t> bytes;
    cv::imencode(format, bgr, bytes);
    for (MessageEncoding encoding : kEncodings) {
      const std::vector<uint8_t> data = testing::SerializeCompressedImage(encoding, 3.5, format + 1, bytes);
      const DecodedImage image = Decode(data, encoding, kCompressedImageType);
      EXPECT_DOUBLE_EQ(image.stamp, 3.5);
      EXPECT_LT(MeanDifference(image.color, bgr), std::string(format) == ".png" ? 0.001 : 3.0);
      EXPECT_EQ(ImageMessageSize(data.data(), data.size(), "sensor_msgs/msg/CompressedImage", encoding, "m"),
                bgr.size());
    }
  }
}

// A depth topic through compressed_image_transport ("16UC1; png compressed ") or compressed_depth_image_transport
// is refused as its raw images are, whatever the PNG decodes to; the colour transport's formats are read.
TEST(RosImageMessages, ACompressedDepthImageIsRefusedAsItsRawImagesAre) {
  cv::Mat depth(48, 64, CV_16UC1, cv::Scalar(1500));
  std::vector<uint8_t> png;
  cv::imencode(".png", depth, png);
  for (MessageEncoding encoding : kEncodings) {
    for (const char* format :
         {"16UC1; png compressed ", "32FC1; compressedDepth", "16UC1; compressedDepth png", "compressedDepth"}) {
      const std::vector<uint8_t> data = testing::SerializeCompressedImage(encoding, 1.0, format, png);
      try {
        Decode(data, encoding, kCompressedImageType);
        ADD_FAILURE() << format << " decoded";
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("depth image's"), std::string::npos) << e.what();
      }
    }
    const std::vector<uint8_t> colour = testing::SerializeCompressedImage(encoding, 1.0, "bgr8; png compressed ", png);
    EXPECT_FALSE(Decode(colour, encoding, kCompressedImageType).gray.empty());
  }
}

// A compressed image of a few bytes may announce 32000 x 32000 pixels (a gigabyte once decoded): refused by its
// header, before the decoder allocates anything.
TEST(RosImageMessages, ACompressedImageAnnouncingTooManyPixelsIsRefusedByItsHeader) {
  std::vector<uint8_t> png;
  cv::imencode(".png", TestImage(), png);
  for (const int at : {16, 20}) {  // IHDR's width, then its height, big-endian
    png[at] = 0;
    png[at + 1] = 0;
    png[at + 2] = 32000 >> 8;
    png[at + 3] = 32000 & 0xff;
  }
  for (MessageEncoding encoding : kEncodings) {
    const std::vector<uint8_t> data = testing::SerializeCompressedImage(encoding, 1.0, "png", png);
    try {
      Decode(data, encoding, kCompressedImageType);
      ADD_FAILURE() << "decoded";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("header announces 32000x32000"), std::string::npos) << e.what();
    }
  }
}

// A JPEG cut short decodes without an error, its missing rows grey: refused as a frame from a file is.
TEST(RosImageMessages, ACompressedJpegCutShortIsRefused) {
  std::vector<uint8_t> jpeg;
  cv::imencode(".jpg", TestImage(), jpeg);
  jpeg.resize(jpeg.size() / 2);
  for (MessageEncoding encoding : kEncodings) {
    const std::vector<uint8_t> data = testing::SerializeCompressedImage(encoding, 1.0, "jpeg", jpeg);
    try {
      Decode(data, encoding, kCompressedImageType);
      ADD_FAILURE() << "decoded";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("holds a JPEG cut short"), std::string::npos) << e.what();
    }
  }
}

TEST(RosImageMessages, MalformedMessagesAreInputErrorsNeverCrashes) {
  const cv::Mat bgr = TestImage();
  for (MessageEncoding encoding : kEncodings) {
    const std::vector<uint8_t> good = testing::SerializeImage(encoding, 1.0, "camera", bgr, "bgr8");
    // Cut anywhere: an error, never a read past the end.
    for (size_t size = 0; size < good.size(); size += 97) {
      EXPECT_THROW(Decode(std::vector<uint8_t>(good.begin(), good.begin() + size), encoding), InputError);
    }
    // Huge lengths in every 4-byte field position.
    for (size_t at = 0; at + 4 <= 64; ++at) {
      std::vector<uint8_t> bad = good;
      bad[at] = bad[at + 1] = bad[at + 2] = bad[at + 3] = 0xff;
      try {
        Decode(bad, encoding);
      } catch (const InputError&) {
      }
    }
    try {
      Decode(testing::SerializeImage(encoding, 1.0, "c", cv::Mat(0, 0, CV_8UC3), "bgr8"), encoding);
      ADD_FAILURE() << "an empty image decoded";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("is an empty image (0x0 bgr8)"), std::string::npos) << e.what();
    }
    std::vector<uint8_t> yuv = testing::SerializeImage(encoding, 1.0, "c", bgr, "yuv422");
    try {
      Decode(yuv, encoding);
      ADD_FAILURE() << "yuv422 decoded";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("mono8, mono16, rgb8"), std::string::npos) << e.what();
    }
    // A depth image (REP 118) is not a grey one, whatever its numbers look like.
    for (const char* depth : {"16UC1", "32FC1"}) {
      const int type = std::string(depth) == "16UC1" ? CV_16UC1 : CV_32FC1;
      try {
        Decode(testing::SerializeImage(encoding, 1.0, "c", cv::Mat(bgr.size(), type, cv::Scalar(1000)), depth),
               encoding);
        ADD_FAILURE() << depth << " decoded";
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("a depth image's (REP 118)"), std::string::npos) << e.what();
      }
    }
  }
}

TEST(RosImageMessages, CameraInfoModels) {
  const cv::Matx33d k(500, 0, 320, 0, 510, 240, 0, 0, 1);
  for (MessageEncoding encoding : kEncodings) {
    const auto decode = [&](const std::string& model, const std::vector<double>& d, const cv::Matx33d& matrix) {
      // "cam" leaves the float64 fields needing CDR padding; "camera_frame" another amount.
      const std::vector<uint8_t> data = testing::SerializeCameraInfo(
          encoding, 2.0, model.size() % 2 ? "cam" : "camera_frame", {640, 480}, model, d, matrix);
      return DecodeCameraInfo(data.data(), data.size(), encoding, "camera info");
    };
    const std::optional<Camera> plumb_bob = decode("plumb_bob", {-0.2, 0.05, 0.001, -0.002, 0.01}, k);
    ASSERT_TRUE(plumb_bob);
    EXPECT_EQ(plumb_bob->fx, 500);
    EXPECT_EQ(plumb_bob->fy, 510);
    EXPECT_EQ(plumb_bob->cx, 320);
    EXPECT_EQ(plumb_bob->cy, 240);
    EXPECT_EQ(plumb_bob->k1, -0.2);
    EXPECT_EQ(plumb_bob->p2, -0.002);
    EXPECT_EQ(plumb_bob->k3, 0.01);
    EXPECT_EQ(plumb_bob->size, cv::Size(640, 480));
    const std::optional<Camera> rational = decode("rational_polynomial", {-0.2, 0.05, 0, 0, 0, 0, 0, 0}, k);
    ASSERT_TRUE(rational);
    EXPECT_EQ(rational->model, CameraModel::kOpenCV);
    const std::optional<Camera> rational_k4 = decode("rational_polynomial", {-0.2, 0.05, 0, 0, 0, 0.1, 0, 0}, k);
    ASSERT_TRUE(rational_k4);
    EXPECT_EQ(rational_k4->model, CameraModel::kFullOpenCV);
    EXPECT_EQ(rational_k4->k4, 0.1);
    EXPECT_EQ(rational_k4->distortion().size(), 8u);
    const std::optional<Camera> fisheye = decode("equidistant", {0.1, 0.01, -0.002, 0.0005}, k);
    ASSERT_TRUE(fisheye);
    EXPECT_EQ(fisheye->model, CameraModel::kOpenCVFisheye);
    EXPECT_EQ(fisheye->distortion(), (std::vector<double>{0.1, 0.01, -0.002, 0.0005}));
    EXPECT_EQ(fisheye->size, cv::Size(640, 480));
    EXPECT_THROW(decode("equidistant", {0.1, 0.01, 0}, k), InputError);
    try {
      decode("kannala_brandt_8", {0.1, 0.01, 0, 0}, k);
      ADD_FAILURE() << "an unknown distortion model accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("--camera"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(decode("plumb_bob", {}, cv::Matx33d::zeros()));  // an uncalibrated camera
  }
}

}  // namespace
}  // namespace vmap
