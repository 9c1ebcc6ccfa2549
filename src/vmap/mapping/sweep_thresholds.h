#pragma once
// The thresholds of a sweep, as given on the command line.

#include <string>
#include <vector>

namespace vmap {

// A sweep runs one key-image selector per threshold, all at once: at most this many.
inline constexpr int kMaxThresholds = 100;

// Parses "0.1:0.9:0.1" (start:stop:step, inclusive) or "0.2,0.5,0.8": 1 to kMaxThresholds distinct thresholds
// in (0, 1]. Malformed text is an OptionError naming "thresholds".
std::vector<double> ParseThresholds(const std::string& text);

}  // namespace vmap
