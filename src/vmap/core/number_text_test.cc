#include "vmap/core/number_text.h"

#include <clocale>
#include <cmath>
#include <cstdlib>

#include <gtest/gtest.h>

#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {

TEST(NumberText, ReadsTheWholeTextAsStrtodDoesInTheCLocale) {
  EXPECT_EQ(ParseNumber("525.06"), 525.06);
  EXPECT_EQ(ParseNumber(" -7.613e-3\t"), -7.613e-3);
  EXPECT_EQ(ParseNumber("-10\r"), -10.0);  // a CRLF file's line
  EXPECT_EQ(ParseNumber("+2"), 2.0);
  EXPECT_EQ(ParseNumber("1e5"), 1e5);
  EXPECT_TRUE(std::isinf(*ParseNumber("inf")));
  EXPECT_TRUE(std::isnan(*ParseNumber("nan")));
  for (const char* none : {"", " ", "abc", "1.5x", "1,5", "0x1", "+-1", "1 2", "--1", "1e400"}) {
    EXPECT_EQ(ParseNumber(none), std::nullopt) << none;
  }
}

// A host program's locale with a decimal comma (Python's locale.setlocale(LC_ALL, "") under de_DE) changes nothing.
// The locale is compiled for the test when the system has none installed (Debian's `locales` has its sources).
TEST(NumberText, TheProcesssLocaleChangesNothing) {
  testing::ScopedTempDir dir("locale");
  const std::string compiled = (dir.path() / "de_DE.UTF-8").string();
  const bool made = std::system(("localedef -i de_DE -f UTF-8 '" + compiled + "' >/dev/null 2>&1").c_str()) == 0;
  if (made) setenv("LOCPATH", dir.path().c_str(), 1);
  const bool set = std::setlocale(LC_NUMERIC, "de_DE.UTF-8") != nullptr;
  const double strtod_reads = std::strtod("525.06", nullptr);
  const std::optional<double> read = ParseNumber("525.06");
  std::setlocale(LC_NUMERIC, "C");
  unsetenv("LOCPATH");
  if (!set) GTEST_SKIP() << "no de_DE locale, and localedef could not make one";
  EXPECT_EQ(strtod_reads, 525.0);  // the failure this guards against
  EXPECT_EQ(read, 525.06);
}

}  // namespace vmap
