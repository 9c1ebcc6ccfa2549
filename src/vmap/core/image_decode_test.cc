#include "vmap/core/image_decode.h"

#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

ContainedFile Open(const fs::path& path) {
  std::string why_not;
  std::optional<ContainedFile> file = ContainedFile::OpenRegular(path, &why_not);
  if (!file) throw std::runtime_error(path.string() + " " + why_not);
  return std::move(*file);
}

}  // namespace

// What is decoded is the file that was opened, whatever its path holds by then: a recorder that replaces a frame's
// file (or a FIFO put in its place) after it was opened and checked does not change what is decoded.
TEST(ImageDecode, DecodesTheFileOpenedNotWhatItsPathHoldsLater) {
  testing::ScopedTempDir tmp;
  const fs::path path = tmp.path() / "frame.png";
  ASSERT_TRUE(cv::imwrite(path.string(), cv::Mat(40, 60, CV_8U, cv::Scalar(7))));
  const ContainedFile opened = Open(path);
  fs::remove(path);
  ASSERT_TRUE(cv::imwrite(path.string(), cv::Mat(50, 70, CV_8U, cv::Scalar(200))));
  std::string why_not;
  const cv::Mat gray = DecodeImageFile(opened, cv::IMREAD_GRAYSCALE, 1 << 20, &why_not);
  ASSERT_FALSE(gray.empty()) << why_not;
  EXPECT_EQ(gray.size(), cv::Size(60, 40));
  EXPECT_EQ(gray.at<unsigned char>(0, 0), 7);
  const cv::Mat color = DecodeImageFile(opened, cv::IMREAD_COLOR, 1 << 20, &why_not);
  EXPECT_EQ(color.type(), CV_8UC3);
  EXPECT_EQ(color.size(), cv::Size(60, 40));
}

TEST(ImageDecode, NamesWhyAFileGivesNoImage) {
  testing::ScopedTempDir tmp;
  const auto why = [&](const fs::path& path, long max_pixels = 1 << 20) {
    std::string why_not;
    const cv::Mat image = DecodeImageFile(Open(path), cv::IMREAD_GRAYSCALE, max_pixels, &why_not);
    EXPECT_TRUE(image.empty()) << path;
    return why_not;
  };
  // A JPEG cut short, which libjpeg would decode with its missing rows grey.
  cv::Mat noise(120, 160, CV_8U);
  cv::randu(noise, 0, 255);
  std::vector<unsigned char> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", noise, jpeg));
  std::ofstream(tmp.path() / "half.jpg", std::ios::binary)
      .write(reinterpret_cast<const char*>(jpeg.data()), static_cast<std::streamsize>(jpeg.size() / 2));
  EXPECT_EQ(why(tmp.path() / "half.jpg"), "is a JPEG cut short (no end-of-image marker)");
  // A header announcing more pixels than asked for is refused before a decoder allocates for it.
  testing::WritePngHeader(tmp.path() / "bomb.png", 32000, 32000);
  EXPECT_EQ(why(tmp.path() / "bomb.png"), "announces 32000x32000 in its header, more than 1048576 pixels");
  ASSERT_TRUE(cv::imwrite((tmp.path() / "small.png").string(), noise));
  EXPECT_EQ(why(tmp.path() / "small.png", 100 * 100), "announces 160x120 in its header, more than 10000 pixels");
  // No image file is this large: refused without reading it (a sparse file takes no disk).
  fs::copy_file(tmp.path() / "small.png", tmp.path() / "huge.png");
  fs::resize_file(tmp.path() / "huge.png", kMaxImageFileBytes + 1);
  EXPECT_EQ(why(tmp.path() / "huge.png"), "is 1073741825 bytes, more than any image file vmap reads (1 GiB)");
  std::ofstream(tmp.path() / "text.png") << "not an image";
  EXPECT_EQ(why(tmp.path() / "text.png"), "cannot be decoded (corrupt or not an image)");
}

}  // namespace vmap
