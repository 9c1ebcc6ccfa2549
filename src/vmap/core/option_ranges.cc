#include "vmap/core/option_ranges.h"

#include <cmath>
#include <limits>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "vmap/core/error.h"

namespace vmap {
namespace {

// A bound as the field's type writes it: an int field's 100000 is "100000", not "1e+05".
std::string Number(double value, bool integral) {
  if (integral && std::abs(value) < 1e15) return fmt::format("{}", static_cast<long long>(value));
  return fmt::format("{}", value);
}

// "is outside [0, 1000]", "is outside (0, 1]", "is less than -1", "is not 0 nor in [1, 1000]", "is not -1 nor
// at least 0".
std::string Describe(const OptionRange& range, bool integral) {
  const std::string min = Number(range.min, integral);
  if (std::isinf(range.max)) {
    if (range.also) {
      return fmt::format("is not {} nor {} {}", Number(*range.also, integral),
                         range.min_excluded ? "above" : "at least", min);
    }
    return fmt::format("is {} {}", range.min_excluded ? "not above" : "less than", min);
  }
  const std::string interval = fmt::format("{}{}, {}{}", range.min_excluded ? "(" : "[", min,
                                           Number(range.max, integral), range.max_excluded ? ")" : "]");
  if (range.also) return fmt::format("is not {} nor in {}", Number(*range.also, integral), interval);
  return "is outside " + interval;
}

}  // namespace

namespace option_ranges_internal {

void RangeChecker::OnField(const OptionField& field, std::optional<double>& value) {
  if (value) {
    Test(field, *value, false);
  } else {
    Test(field, 0.0, false, true);
  }
}

void RangeChecker::Test(const OptionField& field, double value, bool integral, bool optional_unset) {
  if (depth_ > 0 || !field.range.is_set) return;
  if (describing_) {
    if (outside_ && !default_ && Path(field) == outside_->path) {
      default_ = optional_unset ? "unset" : integral ? Number(value, true) : fmt::format("{}", value);
    }
    return;
  }
  if (optional_unset || outside_ || field.range.Contains(value)) return;
  outside_ =
      Outside{Path(field), integral ? Number(value, true) : fmt::format("{}", value), value, field.range, integral};
}

void RangeChecker::ThrowOutside() const {
  const Outside& outside = *outside_;
  const OptionRange& range = outside.range;
  const std::string unit = range.unit != nullptr ? std::string(" ") + range.unit : "";
  // An infinite value within an unbounded range is outside it only by being infinite.
  const bool unbounded_infinity = std::isinf(range.max) && std::isinf(outside.number) && outside.number > 0;
  std::string problem =
      outside.value + unit + " " + (unbounded_infinity ? "is not finite" : Describe(range, outside.integral));
  std::vector<std::string> notes;
  if (default_) notes.push_back("default " + *default_ + unit);
  if (range.meaning != nullptr) notes.push_back(range.meaning);
  if (!notes.empty()) problem += " (" + fmt::format("{}", fmt::join(notes, "; ")) + ")";
  throw OptionError(outside.path, problem);
}

}  // namespace option_ranges_internal

std::string RangeText(const OptionRange& range, bool integral) {
  // An int without a bound of its own ends where an int does: a larger number is no value of it (CLI11 refuses it).
  const bool unbounded = std::isinf(range.max);
  const std::string max = !unbounded ? Number(range.max, integral)
                          : integral ? Number(std::numeric_limits<int>::max(), true)
                                     : "inf";
  const std::string interval = fmt::format("{}{}, {}{}", range.min_excluded ? "(" : "[", Number(range.min, integral),
                                           max, range.max_excluded || (unbounded && !integral) ? ")" : "]");
  return range.also ? Number(*range.also, integral) + " or " + interval : interval;
}

}  // namespace vmap
