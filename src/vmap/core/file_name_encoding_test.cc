#include "vmap/core/file_name_encoding.h"

#include <random>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace vmap {

TEST(FileNameEncoding, KeepsValidUtf8AndEncodesTheRest) {
  struct Case {
    std::string bytes, text;
  };
  const std::vector<Case> cases = {
      {"frame_0001.png", "frame_0001.png"},
      {"caf\xC3\xA9.png", "caf\xC3\xA9.png"},                            // UTF-8 é stays
      {"\xE6\x97\xA5\xE6\x9C\xAC.jpg", "\xE6\x97\xA5\xE6\x9C\xAC.jpg"},  // CJK stays
      {"\xF0\x9F\x93\xB7.png", "\xF0\x9F\x93\xB7.png"},                  // 4-byte emoji stays
      {"caf\xE9.png", "caf%E9.png"},                                     // Latin-1 é
      {"100%.png", "100%25.png"},                                        // '%' itself
      {"%41", "%2541"},
      {"\xFF\xFE", "%FF%FE"},
      {"\xC3", "%C3"},                                   // truncated sequence
      {"\xC0\xAF", "%C0%AF"},                            // overlong '/'
      {"\xED\xA0\x80", "%ED%A0%80"},                     // UTF-16 surrogate
      {"\xF4\x90\x80\x80", "%F4%90%80%80"},              // above U+10FFFF
      {std::string("a\0b", 3), std::string("a\0b", 3)},  // NUL is valid UTF-8 (JSON escapes it)
  };
  for (const Case& c : cases) {
    EXPECT_EQ(EncodeFileName(c.bytes), c.text) << c.text;
    EXPECT_EQ(DecodeFileName(c.text), c.bytes) << c.text;
    EXPECT_TRUE(IsValidUtf8(EncodeFileName(c.bytes))) << c.text;
  }
}

TEST(FileNameEncoding, EveryByteStringRoundTripsThroughJson) {
  std::mt19937 random(5);
  for (int trial = 0; trial < 2000; ++trial) {
    std::string bytes(random() % 24, '\0');
    for (char& c : bytes) c = static_cast<char>(random() % 256);
    // Through nlohmann-json, which refuses to write invalid UTF-8.
    const std::string text = nlohmann::json(EncodeFileName(bytes)).dump();
    EXPECT_EQ(DecodeFileName(nlohmann::json::parse(text).get<std::string>()), bytes);
  }
}

TEST(FileNameEncoding, DecodingKeepsAPercentThatIsNotAnEscape) {
  EXPECT_EQ(DecodeFileName("50%off"), "50%off");
  EXPECT_EQ(DecodeFileName("end%"), "end%");
  EXPECT_EQ(DecodeFileName("end%4"), "end%4");
  EXPECT_EQ(DecodeFileName("%e9"), "\xE9");
}

TEST(FileNameEncoding, Utf8Validation) {
  EXPECT_TRUE(IsValidUtf8(""));
  EXPECT_TRUE(IsValidUtf8("plain"));
  EXPECT_TRUE(IsValidUtf8("\xEF\xBF\xBD"));
  EXPECT_FALSE(IsValidUtf8("\x80"));
  EXPECT_FALSE(IsValidUtf8("\xE0\x80\x80"));  // overlong
  EXPECT_FALSE(IsValidUtf8("\xF5\x80\x80\x80"));
}

}  // namespace vmap
