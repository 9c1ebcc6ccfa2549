#include "vmap/core/terminal_text.h"

#include <gtest/gtest.h>

namespace vmap {
namespace {

TEST(TerminalText, ControlCharactersAreWrittenAsEscapes) {
  EXPECT_EQ(TerminalSafe("keys/000012.png"), "keys/000012.png");
  EXPECT_EQ(TerminalSafe("caf\xc3\xa9 \xe9.png\tok"), "caf\xc3\xa9 \xe9.png\tok");  // UTF-8, Latin-1, a tab
  EXPECT_EQ(TerminalSafe("a\x1b[2Jb.png"), "a\\x1b[2Jb.png");                       // would clear the screen
  EXPECT_EQ(TerminalSafe("topics:\n  /a\n  /b"), "topics:\n  /a\n  /b");            // messages list things on lines
  EXPECT_EQ(TerminalSafe("a.png\r[error] over"), "a.png\\r[error] over");           // would overwrite the line
  EXPECT_EQ(TerminalSafe("\x7f\b"), "\\x7f\\x08");
  EXPECT_EQ(TerminalSafe("x\xc2\x9b"
                         "31m"),
            "x\\xc2\\x9b31m");                              // CSI as a C1 control
  EXPECT_EQ(TerminalSafe("\xc2\xa0\xc2"), "\xc2\xa0\xc2");  // no-break space; a cut sequence kept
  EXPECT_EQ(TerminalSafe("a\x9b"
                         "31m"),
            "a\\x9b31m");                                                    // a lone C1 byte (8-bit terminals)
  EXPECT_EQ(TerminalSafe("\xe2\x80\x9c\xe9\x9b"), "\xe2\x80\x9c\xe9\\x9b");  // in a sequence kept; after Latin-1 not
  EXPECT_EQ(TerminalSafe(std::string_view("a\0b", 3)), "a\\x00b");
}

}  // namespace
}  // namespace vmap
