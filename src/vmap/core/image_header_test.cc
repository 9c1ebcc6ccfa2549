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

}  // namespace vmap
