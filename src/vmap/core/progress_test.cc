#include "vmap/core/progress.h"

#include <cstdio>

#include <gtest/gtest.h>

namespace vmap {

TEST(Progress, FormatShowsRateAndEta) {
  const std::string text = ProgressLine::Format("build", 100, 400, "frames", 2.0);
  EXPECT_NE(text.find("100/400 frames (25%)"), std::string::npos) << text;
  EXPECT_NE(text.find("50.0 frames/s"), std::string::npos) << text;
  EXPECT_NE(text.find("ETA 6s"), std::string::npos) << text;  // 300 frames at 50/s
}

TEST(Progress, FormatWithoutTotalHasNoEta) {
  const std::string text = ProgressLine::Format("build", 10, 0, "frames", 1.0);
  EXPECT_EQ(text.find("ETA"), std::string::npos) << text;
  EXPECT_NE(text.find("10.0 frames/s"), std::string::npos) << text;
}

TEST(Progress, SilentWhenNotATerminalOrQuiet) {
  char* buffer = nullptr;
  size_t size = 0;
  FILE* stream = open_memstream(&buffer, &size);
  {
    ProgressLine line("build", 10, "frames", {}, stream);  // a memory stream is not a terminal
    for (int i = 1; i <= 10; ++i) line.Update(i);
  }
  {
    ProgressOptions quiet;
    quiet.enabled = false;
    quiet.force = true;
    ProgressLine line("build", 10, "frames", quiet, stream);
    line.Update(5);
  }
  std::fflush(stream);
  EXPECT_EQ(size, 0u);
  {
    ProgressOptions forced;
    forced.force = true;
    ProgressLine line("build", 10, "frames", forced, stream);
    line.Update(10);
  }
  std::fflush(stream);
  EXPECT_NE(std::string(buffer, size).find("10/10 frames"), std::string::npos);
  std::fclose(stream);
  free(buffer);
}

}  // namespace vmap
