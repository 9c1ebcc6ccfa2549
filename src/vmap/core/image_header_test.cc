#include "vmap/core/image_header.h"

#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

std::optional<cv::Size> SizeOf(const fs::path& path) {
  std::string why_not;
  const std::optional<ContainedFile> file = ContainedFile::OpenRegular(path, &why_not);
  EXPECT_TRUE(file) << why_not;
  return file ? ImageHeaderSize(*file) : std::nullopt;
}

}  // namespace

TEST(ImageHeader, SizesAreReadWithoutDecoding) {
  testing::ScopedTempDir tmp;
  cv::imwrite((tmp.path() / "a.png").string(), cv::Mat(48, 64, CV_8UC3, cv::Scalar(1, 2, 3)));
  cv::imwrite((tmp.path() / "b.jpg").string(), cv::Mat(30, 70, CV_8U, cv::Scalar(9)));
  cv::imwrite((tmp.path() / "c.bmp").string(), cv::Mat(30, 70, CV_8U, cv::Scalar(9)));
  EXPECT_EQ(SizeOf(tmp.path() / "a.png"), cv::Size(64, 48));
  EXPECT_EQ(SizeOf(tmp.path() / "b.jpg"), cv::Size(70, 30));
  EXPECT_EQ(SizeOf(tmp.path() / "c.bmp"), std::nullopt);  // another format: the decoder's checks apply
  // A header that announces a gigapixel image, with nothing behind it.
  testing::WritePngHeader(tmp.path() / "bomb.png", 32000, 32000);
  EXPECT_EQ(SizeOf(tmp.path() / "bomb.png"), cv::Size(32000, 32000));
  std::ofstream(tmp.path() / "cut.png") << "\x89PNG";
  EXPECT_EQ(SizeOf(tmp.path() / "cut.png"), std::nullopt);
}

// A JPEG cut short decodes without an error, its missing rows grey: told by its missing end-of-image marker; a PNG by
// its missing IEND chunk.
TEST(ImageHeader, AJpegOrPngCutShortIsToldFromAWholeOne) {
  testing::ScopedTempDir tmp;
  cv::Mat noise(240, 320, CV_8UC3);
  cv::randu(noise, 0, 255);
  ASSERT_TRUE(cv::imwrite((tmp.path() / "whole.jpg").string(), noise));
  std::ifstream in(tmp.path() / "whole.jpg", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream(tmp.path() / "half.jpg", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  std::ofstream(tmp.path() / "trailer.jpg", std::ios::binary) << bytes << std::string(1000, 'x');
  ASSERT_TRUE(cv::imwrite((tmp.path() / "a.png").string(), noise));
  const auto cut_short = [&](const char* name) {
    std::string why_not;
    const std::optional<ContainedFile> file = ContainedFile::OpenRegular(tmp.path() / name, &why_not);
    EXPECT_TRUE(file) << why_not;
    return file && CutShortImage(*file) != nullptr;
  };
  EXPECT_FALSE(cut_short("whole.jpg"));
  EXPECT_TRUE(cut_short("half.jpg"));
  EXPECT_FALSE(cut_short("trailer.jpg"));  // data after the marker (a camera's own) is no cut
  EXPECT_FALSE(cut_short("a.png"));
  // A PNG cut short (a full disk while a map was written): its header is whole, its IEND chunk missing.
  std::ifstream png_in(tmp.path() / "a.png", std::ios::binary);
  const std::string png((std::istreambuf_iterator<char>(png_in)), std::istreambuf_iterator<char>());
  std::ofstream(tmp.path() / "half.png", std::ios::binary) << png.substr(0, png.size() / 2);
  std::ofstream(tmp.path() / "trailer.png", std::ios::binary) << png << std::string(1000, 'x');
  EXPECT_TRUE(cut_short("half.png"));
  EXPECT_FALSE(cut_short("trailer.png"));
  // The half decodes all the same: why the marker is asked for.
  EXPECT_FALSE(cv::imread((tmp.path() / "half.jpg").string()).empty());
}

}  // namespace vmap
