// The build-time embedding of files (embed_assets.cmake), checked on a file of bytes that would break a
// string literal, a raw string or a comment.

#include <fstream>
#include <iterator>
#include <string>
#include <string_view>

#include <gtest/gtest.h>

namespace vmap::report {
std::string_view EmbedTestAsset();  // generated from testdata/embed_edge_cases.bin (report/CMakeLists.txt)
}  // namespace vmap::report

namespace vmap {

TEST(EmbedAssets, EmbedsEveryByteOfTheFileExactly) {
  std::ifstream file(VMAP_EMBED_TEST_FILE, std::ios::binary);
  ASSERT_TRUE(file) << VMAP_EMBED_TEST_FILE;
  const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  // The file holds what makes embedding hard: NUL, the end of a raw string, quotes, backslashes, bytes
  // that are not UTF-8, and no final line break.
  ASSERT_NE(bytes.find('\0'), std::string::npos);
  ASSERT_NE(bytes.find(")css\""), std::string::npos);
  ASSERT_NE(bytes.find('\xff'), std::string::npos);
  ASSERT_NE(bytes.back(), '\n');
  EXPECT_EQ(std::string(report::EmbedTestAsset()), bytes);
}

}  // namespace vmap
