#pragma once
// Small text helpers shared by the HTML report and the SVG plots.

#include <string>
#include <string_view>

namespace vmap::report {

// Escapes &, <, >, " and ' so that any text (a file name, a JSON option) is safe inside HTML text and
// attribute values.
std::string HtmlEscape(std::string_view text);

// Fixed-point text with `decimals` digits ("0.41"); never prints "-0.00".
std::string FormatFixed(double value, int decimals);

// The shortest of "%.*g"-style text that reads back as the same double: for data-* attributes that tests
// and scripts parse back.
std::string FormatExact(double value);

// A path written the way an HTML attribute expects it: '/' separators, each segment percent-encoded where
// it is not a plain URL character.
std::string UrlPath(const std::string& generic_path);

}  // namespace vmap::report
