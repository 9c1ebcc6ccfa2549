#include "vmap/core/image_file.h"

#include <sys/resource.h>
#include <sys/stat.h>

#include <csignal>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "vmap/core/error.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace {
namespace fs = std::filesystem;

cv::Mat Noise(int side) {
  cv::Mat image(side, side, CV_8UC3);
  cv::randu(image, cv::Scalar::all(0), cv::Scalar::all(255));  // incompressible: its PNG is as large as its pixels
  return image;
}

std::string WriteError(const fs::path& path, const cv::Mat& image) {
  try {
    WriteImageFile(path, image, "key image");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ImageFile, WritesWhatDecodesBackAndNamesEveryFailure) {
  testing::ScopedTempDir tmp;
  const cv::Mat image = Noise(64);
  WriteImageFile(tmp.path() / "a.png", image, "key image");
  EXPECT_EQ(cv::norm(cv::imread((tmp.path() / "a.png").string()), image, cv::NORM_INF), 0.0);
  WriteImageFile(tmp.path() / "a.jpg", image, "key image", {cv::IMWRITE_JPEG_QUALITY, 90});
  EXPECT_EQ(cv::imread((tmp.path() / "a.jpg").string()).size(), image.size());

  EXPECT_NE(WriteError(tmp.path() / "no/a.png", image).find("(No such file or directory)"), std::string::npos);
  EXPECT_NE(WriteError(tmp.path() / "a.gif", image).find("cannot encode key image"), std::string::npos);
  // Neither followed through a link nor written into a device or a FIFO (nor waited on), nor removed.
  fs::create_symlink("/dev/full", tmp.path() / "full.png");
  EXPECT_NE(WriteError(tmp.path() / "full.png", image), "");
  EXPECT_TRUE(fs::exists("/dev/full"));
  ASSERT_EQ(mkfifo((tmp.path() / "fifo.png").c_str(), 0600), 0);
  EXPECT_NE(WriteError(tmp.path() / "fifo.png", image), "");
  EXPECT_TRUE(fs::is_fifo(tmp.path() / "fifo.png"));

  // A write that fails part way (the file size limit stands in for a full disk: both fail write(2) mid-file): an
  // error with the system's reason, and no file cut short left behind.
  struct rlimit old_limit {};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old_limit), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  struct rlimit small = old_limit;
  small.rlim_cur = 4096;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  const std::string error = WriteError(tmp.path() / "large.png", Noise(256));
  setrlimit(RLIMIT_FSIZE, &old_limit);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_NE(error.find("cannot write key image '"), std::string::npos) << error;
  EXPECT_NE(error.find("(File too large)"), std::string::npos) << error;
  EXPECT_FALSE(fs::exists(tmp.path() / "large.png"));
}

}  // namespace
}  // namespace vmap
