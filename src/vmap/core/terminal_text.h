#pragma once
// Text for a terminal or a log. A file name may hold any byte but '/' and NUL: an ESC in it would recolour or
// clear the terminal when a warning prints the name, a carriage return would overwrite the line. Such characters
// are written as escapes ("\x1b", "\r") so that what a user reads is what the name holds. Line breaks are kept:
// vmap's messages use them to list things (a recording's topics, a weights file's keys).

#include <string>
#include <string_view>

namespace vmap {

// `text` with every control character (C0 but the tab and the line feed, DEL, the C1 controls U+0080-U+009F of
// UTF-8, and bytes 0x80-0x9F outside a UTF-8 sequence) written as a C escape: \r, or \xNN per byte. Everything
// else, other invalid UTF-8 included, is kept.
std::string TerminalSafe(std::string_view text);

}  // namespace vmap
