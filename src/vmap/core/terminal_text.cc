#include "vmap/core/terminal_text.h"

#include <fmt/format.h>

namespace vmap {
namespace {

// The length of the UTF-8 sequence starting at `i` when its continuation bytes are all there, else 0.
size_t SequenceLength(std::string_view text, size_t i) {
  const auto lead = static_cast<unsigned char>(text[i]);
  const size_t length = lead >= 0xF0 ? 4 : lead >= 0xE0 ? 3 : lead >= 0xC0 ? 2 : 0;
  if (length == 0 || i + length > text.size()) return 0;
  for (size_t k = 1; k < length; ++k) {
    if ((static_cast<unsigned char>(text[i + k]) & 0xC0) != 0x80) return 0;
  }
  return length;
}

}  // namespace

std::string TerminalSafe(std::string_view text) {
  std::string safe;
  safe.reserve(text.size());
  for (size_t i = 0; i < text.size(); ++i) {
    const auto byte = static_cast<unsigned char>(text[i]);
    if (const size_t length = SequenceLength(text, i); length > 0) {
      const auto second = static_cast<unsigned char>(text[i + 1]);
      if (byte == 0xC2 && second <= 0x9F) {  // U+0080-U+009F: a C1 control
        safe += fmt::format("\\xc2\\x{:02x}", second);
      } else {
        safe.append(text.substr(i, length));
      }
      i += length - 1;
    } else if (byte == '\r') {
      safe += "\\r";
    } else if ((byte < 0x20 && byte != '\t' && byte != '\n') || byte == 0x7F || (byte >= 0x80 && byte <= 0x9F)) {
      // C0 controls, DEL, and 0x80-0x9F outside a UTF-8 sequence: C1 controls to a terminal in an 8-bit mode.
      safe += fmt::format("\\x{:02x}", byte);
    } else {
      safe += text[i];
    }
  }
  return safe;
}

}  // namespace vmap
