#pragma once
// The order people give numbered file names: "img2" before "img10".

#include <string>

namespace vmap {

// "img2" < "img10": digit runs compare as numbers, and the digits after a number's point as decimals
// ("10.05" < "10.5").
bool NaturalLess(const std::string& a, const std::string& b);

}  // namespace vmap
