#include "vmap/report/html_util.h"

#include <cmath>

#include <fmt/format.h>

#include "vmap/core/number_text.h"

namespace vmap::report {

std::string HtmlEscape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string FormatFixed(double value, int decimals) {
  if (!std::isfinite(value)) return "n/a";
  // fmt, not printf: the same text whatever the process's locale (a decimal comma in the HTML's numbers broke them).
  std::string text = fmt::format("{:.{}f}", value, decimals);
  // "-0.00" reads as a sign error in a table.
  if (text[0] == '-' && text.find_first_not_of("-0.") == std::string::npos) text.erase(0, 1);
  return text;
}

std::string FormatExact(double value) {
  std::string text;
  for (int precision = 6; precision <= 17; ++precision) {
    text = fmt::format("{:.{}g}", value, precision);
    if (ParseNumber(text) == value) break;
  }
  return text;
}

std::string UrlPath(const std::string& generic_path) {
  static const char* kHex = "0123456789ABCDEF";
  std::string out;
  for (unsigned char c : generic_path) {
    const bool plain = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' ||
                       c == '_' || c == '.' || c == '~' || c == '/';
    if (plain) {
      out += static_cast<char>(c);
    } else {
      out += '%';
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  return out;
}

}  // namespace vmap::report
