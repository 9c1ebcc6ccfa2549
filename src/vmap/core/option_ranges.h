#pragma once
// An options struct's Check() of the values its number fields take, as its field list gives them
// (OptionField::Within, core/option_fields.h): the ranges are written once, beside each field's key, flag and
// help, and the checks and their messages follow. A check of several fields stays in the struct's Check().
//
//   void LocalizerOptions::Check() const {
//     CheckFieldRanges(*this);  // "lookahead 3 is outside [1, 2] (default 2)"
//     CheckField("belief", belief);
//     ...
//   }
//
// Cheap enough for a check on every call (EstimateHeading checks its options each time): the values are only
// compared; the defaults are read and the message written only for a value outside its range.

#include <optional>
#include <string>
#include <vector>

#include "vmap/core/option_fields.h"

namespace vmap {

namespace option_ranges_internal {

// Visits a struct's own fields (not those of the structs it holds: their own Check() tests them, named by
// CheckField). Checking, it keeps the first field outside its range; describing, it finds that field's default
// in a default-constructed struct and throws the OptionError.
class RangeChecker : public OptionFieldVisitor {
 public:
  bool found_outside() const { return outside_.has_value(); }
  void DescribeWithDefaults() { describing_ = true; }
  [[noreturn]] void ThrowOutside() const;  // after visiting the defaults

 protected:
  void OnField(const OptionField& field, int& value) override { Test(field, value, true); }
  void OnField(const OptionField& field, double& value) override { Test(field, value, false); }
  void OnField(const OptionField& field, std::optional<double>& value) override;
  void OnField(const OptionField& /*field*/, bool& /*value*/) override {}
  void OnField(const OptionField& /*field*/, std::string& /*value*/) override {}
  void OnField(const OptionField& /*field*/, std::vector<int>& /*value*/) override {}
  void OnField(const OptionField& /*field*/, const EnumField& /*value*/) override {}
  void OnEnter(const char* /*name*/, bool /*json_inline*/) override { ++depth_; }
  void OnLeave(bool /*json_inline*/) override { --depth_; }

 private:
  struct Outside {
    std::string path, value;  // the value as written
    double number;
    OptionRange range;
    bool integral;
  };
  // `optional_unset`: an optional number without a value (its range is not tested; its default reads "unset").
  void Test(const OptionField& field, double value, bool integral, bool optional_unset = false);

  int depth_ = 0;
  bool describing_ = false;
  std::optional<Outside> outside_;
  std::optional<std::string> default_;  // the outside field's default, as written
};

}  // namespace option_ranges_internal

// The values a range takes, as a command's help shows them: "[1, 2]", "(0, 1]", "[-1, inf)" (an int's:
// "[-1, 2147483647]"), "0 or [1, 1000]".
// `integral`: the field is an int (its bounds written as integers).
std::string RangeText(const OptionRange& range, bool integral);

// Throws OptionError for the first of `options`' own number fields outside its range: "<path> <value> [unit] is
// outside [min, max] (default <d> [unit]; <meaning>)".
template <typename Options>
void CheckFieldRanges(const Options& options) {
  Options values = options;  // visitors take fields by reference; the copy keeps the check read-only
  option_ranges_internal::RangeChecker checker;
  checker.VisitNested("", values);
  if (!checker.found_outside()) return;
  Options defaults;
  checker.DescribeWithDefaults();
  checker.VisitNested("", defaults);
  checker.ThrowOutside();
}

}  // namespace vmap
