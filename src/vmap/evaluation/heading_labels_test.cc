#include "vmap/evaluation/heading_labels.h"

#include <fstream>

#include <gtest/gtest.h>

#include "vmap/core/error.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace {

std::string WriteCsv(const testing::ScopedTempDir& dir, const std::string& text) {
  const std::string path = (dir.path() / "gt.csv").string();
  std::ofstream(path) << text;
  return path;
}

TEST(HeadingLabels, ReadsEveryRowAfterTheHeader) {
  const testing::ScopedTempDir dir("heading_labels");
  const auto labels =
      ReadHeadingLabels(WriteCsv(dir,
                                 "repeat_image,teach_image,dx_px\nimages/0201.png,images/0101.png,-12.5\n"
                                 "images/0301.png,images/0101.png,40\n"));
  ASSERT_EQ(labels.size(), 2u);
  EXPECT_EQ(labels[0].repeat_image, "images/0201.png");
  EXPECT_EQ(labels[0].teach_image, "images/0101.png");
  EXPECT_DOUBLE_EQ(labels[0].dx_px, -12.5);
  EXPECT_DOUBLE_EQ(labels[1].dx_px, 40.0);
}

TEST(HeadingLabels, AMalformedRowOrAMissingFileNamesTheFile) {
  const testing::ScopedTempDir dir("heading_labels");
  const std::string path = WriteCsv(dir, "repeat_image,teach_image,dx_px\na.png,b.png,1\na.png,b.png,left\n");
  try {
    ReadHeadingLabels(path);
    FAIL() << "a row without a number was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path + " line 3"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ReadHeadingLabels((dir.path() / "missing.csv").string()), InputError);
}

}  // namespace
}  // namespace vmap
