#include "vmap/core/temporary_name.h"

#include <unistd.h>

#include <gtest/gtest.h>

namespace vmap {

TEST(TemporaryName, AMessageNamesTheOutputAFileWasWrittenInto) {
  const std::string inside = TemporarySibling("/data/run 1/m.v2", "partial").string() + "/keys/000000.png";
  EXPECT_EQ(NameOutputsNotTemporaries("cannot write key image '" + inside + "' (File too large)"),
            "cannot write key image '/data/run 1/m.v2/keys/000000.png' (File too large)");
  // Relative, nested, and each tag.
  for (const char* tag : {"partial", "old", "tmp"}) {
    const std::string nested = TemporarySibling(TemporarySibling("m", tag) / "report", "partial").string();
    EXPECT_EQ(NameOutputsNotTemporaries("'" + nested + "/a.jpg'"), "'./m/report/a.jpg'") << nested;
  }
}

TEST(TemporaryName, ATemporaryNamedAloneAndLookAlikesStayAsTheyAre) {
  // Where a finished output was kept when it could not be put in place, the message names the temporary itself.
  const std::string kept = "the finished output is kept at '" + TemporarySibling("/d/m", "partial").string() + "'";
  EXPECT_EQ(NameOutputsNotTemporaries(kept), kept);
  for (const std::string& text : {std::string("'/d/.m.partial-12-x/a'"), std::string("'/d/a.m.partial-12-3/a'"),
                                  std::string("'/d/.m.partial/a'"), std::string("no path at all")}) {
    EXPECT_EQ(NameOutputsNotTemporaries(text), text);
  }
}

TEST(TemporaryName, TheOwnerIsReadBackFromTheName) {
  const std::string name = TemporarySibling("/d/m", "tmp").filename().string();
  EXPECT_EQ(TemporaryOwner(name, "m"), static_cast<long>(getpid()));
  EXPECT_EQ(TemporaryOwner(name, "n"), 0);
  EXPECT_EQ(TemporaryOwner(".m.tmp-12", "m"), 0);
}

}  // namespace vmap
