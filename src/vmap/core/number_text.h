#pragma once
// Numbers read from text (calibration files, CSVs, the --camera and --thresholds options) in the one syntax that C,
// Python and JSON write, whatever the process's locale. std::stod, strtod and sscanf follow LC_NUMERIC, which the
// program vmap runs in may set: Python's locale.setlocale(LC_ALL, "") under de_DE read "525.06" as 525, and a map
// was built with k1 = -7 instead of -0.0076 without a word.

#include <optional>
#include <string_view>

namespace vmap {

// The whole of `text`, white space around it aside (a CRLF line's "\r"), as a number ("-1.5e-3", "+2", "inf", "nan", as
// strtod reads them in the C locale; no hexadecimal); nullopt when it is none or anything else follows it.
std::optional<double> ParseNumber(std::string_view text);

}  // namespace vmap
