#include "vmap/core/number_text.h"

#include <charconv>

namespace vmap {

std::optional<double> ParseNumber(std::string_view text) {
  // White space around it as strtod skips it before and a line's end leaves it after ("-10\r" of a CRLF file).
  constexpr std::string_view kSpace = " \t\r\n\v\f";
  const size_t first = text.find_first_not_of(kSpace);
  if (first == std::string_view::npos) return std::nullopt;
  text = text.substr(first, text.find_last_not_of(kSpace) + 1 - first);
  // std::from_chars reads no locale (the reason it is used here) and no leading '+', which strtod takes.
  if (text.size() > 1 && text[0] == '+' && text[1] != '-') text.remove_prefix(1);
  double value = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

}  // namespace vmap
