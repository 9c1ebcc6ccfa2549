#pragma once
// One field list per options struct, from which its JSON (map.json's, sweep.json's, eval.json's and the
// localization run's "options"; core/options_json.h) and its command-line flags (cli/option_binder.h) are
// derived, so that a field's key, flag, help and default are written once; so are the Python module's keywords
// (python/keyword_options.h). An options struct lists its fields:
//
//   void VerifierOptions::VisitFields(OptionFieldVisitor& visitor) {
//     visitor.Visit(OptionField{"method", "--verifier", "Fundamental matrix estimator: "}.ListingNames(),
//                   EnumField(method, kVerifierMethodNames, ParseVerifierMethod));
//     visitor.Visit({"threshold", "--threshold", "Verifier inlier threshold in pixels"}, threshold);
//     ...
//   }
//
// and a struct holding another visits it by name (`visitor.VisitNested("verifier", verifier)`): its fields'
// paths become "verifier.threshold", the paths OptionError names. Readers and writers are visitors; none of
// them knows the struct. A number field also says which values it takes (`.Within(0, 1000).Or(-1)`), from which
// the struct's Check() tests it (core/option_ranges.h) and the message names them.

#include <cmath>
#include <cstddef>
#include <cstring>
#include <functional>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "vmap/core/enum_names.h"
#include "vmap/core/error.h"

namespace vmap {

// The values a number field takes: [min, max] (either end excluded, max infinite for "at least min"), and one
// value outside it that means something of its own (-1: "the map's"; 0: "never").
struct OptionRange {
  bool is_set = false;  // a field without a range takes any value its type holds
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_excluded = false;
  bool max_excluded = false;
  std::optional<double> also;
  // What the ends or `also` mean, for the message: "0: never". The field's help says it too, for the flag.
  const char* meaning = nullptr;
  const char* unit = nullptr;  // written after the value and the default: "-1 px is outside (0, 100]"

  bool Contains(double value) const {  // NaN and infinities are outside every range
    if (also && value == *also) return true;
    return std::isfinite(value) && (min_excluded ? value > min : value >= min) &&
           (max_excluded ? value < max : value <= max);
  }
};

struct OptionField {
  const char* key;           // the name in JSON and, unless `name` is set, in option paths
  const char* flag = "";     // the command-line flag; "" = none. "!--no-x" is a bool flag that sets false.
                             // Several fields may share a flag (the matchers' --weights): it then sets each.
  const char* help = "";     // the flag's help
  bool show_default = true;  // --help shows the default (off where the default means "the preset's")
  // A file recorded where a map was built (weights): when a map read on another machine names a file that is
  // not here, it is cleared, so that the model searches its weights directories instead.
  bool is_local_file = false;
  bool recorded = true;            // written to and read from JSON; off for how a run is carried out (threads)
  const char* name = nullptr;      // the field's name in option paths where it differs from its JSON key
  bool omit_empty = false;         // a string written only when it is not empty
  const char* empty_as = nullptr;  // the JSON name of an empty string ("input": the input's own camera)
  bool lists_names = false;        // an enum's help ends with its names ("... : auto, sequential or bisect")
  // A positional argument of the command line (required; its flag is its name, "input"): what a command works
  // on, not one of its options (the Python module takes it as an argument, not a keyword).
  bool positional = false;
  OptionRange range = {};

  // Attributes beyond the first three, set by name: OptionField{"camera", "--camera", "..."}.EmptyAs("input").
  OptionField HideDefault() const { return With(&OptionField::show_default, false); }
  OptionField LocalFile() const { return With(&OptionField::is_local_file, true); }
  OptionField NotRecorded() const { return With(&OptionField::recorded, false); }
  OptionField Named(const char* path_name) const { return With(&OptionField::name, path_name); }
  OptionField OmitEmpty() const { return With(&OptionField::omit_empty, true); }
  OptionField EmptyAs(const char* json_name) const { return With(&OptionField::empty_as, json_name); }
  OptionField ListingNames() const { return With(&OptionField::lists_names, true); }
  OptionField Positional() const { return With(&OptionField::positional, true).HideDefault().NotRecorded(); }
  // The values the field takes: Within(0, 1) is [0, 1]; AtLeast(1) is 1 or more; then ExcludingMin() makes it
  // (0, 1], ExcludingMax() [0, 1); Or(0) takes 0 besides; Meaning("0: never") says what a value means; Unit("px")
  // is the value's unit.
  OptionField Within(double min, double max) const {
    OptionField copy = *this;
    copy.range.is_set = true;
    copy.range.min = min;
    copy.range.max = max;
    return copy;
  }
  OptionField AtLeast(double min) const { return Within(min, std::numeric_limits<double>::infinity()); }
  OptionField ExcludingMin() const { return WithRange(&OptionRange::min_excluded, true); }
  OptionField ExcludingMax() const { return WithRange(&OptionRange::max_excluded, true); }
  OptionField Or(double value) const { return WithRange(&OptionRange::also, std::optional<double>(value)); }
  OptionField Meaning(const char* text) const { return WithRange(&OptionRange::meaning, text); }
  OptionField Unit(const char* unit) const { return WithRange(&OptionRange::unit, unit); }

  const char* path_name() const { return name != nullptr ? name : key; }

 private:
  template <typename T>
  OptionField With(T OptionField::*member, T value) const {
    OptionField copy = *this;
    copy.*member = value;
    return copy;
  }
  template <typename T>
  OptionField WithRange(T OptionRange::*member, T value) const {
    OptionField copy = *this;
    copy.range.*member = value;
    return copy;
  }
};

// An enum field seen through its name table (core/enum_names.h), so that visitors need not know the enum.
class EnumField {
 public:
  // `parse` reads a name given by a user (an unknown one is its InputError, e.g. "unknown verifier 'x'; use
  // ..."); map.json's names are read with the table (JsonFieldReader names the key instead).
  template <typename Enum, std::size_t N>
  EnumField(Enum& value, const EnumName<Enum> (&names)[N], Enum (*parse)(const std::string&))
      : name_([&value, &names] { return std::string(EnumToName(names, value)); }),
        set_([&value, &names](const std::string& name) {
          const std::optional<Enum> found = FindEnum(names, name);
          if (found) value = *found;
          return found.has_value();
        }),
        parse_([&value, parse](const std::string& name) { value = parse(name); }),
        names_(ListEnumNames(names)) {}

  std::string name() const { return name_(); }                    // the value's name
  bool Set(const std::string& name) const { return set_(name); }  // false (value kept) for an unknown name
  void Parse(const std::string& name) const { parse_(name); }     // InputError for an unknown name
  const std::string& names() const { return names_; }             // "a, b or c"

 private:
  std::function<std::string()> name_;
  std::function<bool(const std::string&)> set_;
  std::function<void(const std::string&)> parse_;
  std::string names_;
};

// The --help sections several options structs share (OptionFieldVisitor::Section): what a command writes, what it
// reads, and how it is carried out rather than what it computes (threads, caches, seeds).
inline constexpr char kOutputSection[] = "Output";
inline constexpr char kInputSection[] = "Input";
inline constexpr char kRunSection[] = "Run: threads, caches and seeds";

// How a nested struct is visited (OptionFieldVisitor::VisitNested).
struct Nesting {
  // Its fields are written at the level of the struct holding it (map.json's "tau", not "key_images.tau"),
  // while their paths keep its name.
  bool json_inline = false;
  // Fields and nested structs (by key) that this holder does not use: neither recorded nor given a flag.
  std::vector<const char*> skip;
};

class OptionFieldVisitor {
 public:
  virtual ~OptionFieldVisitor() = default;

  void Visit(const OptionField& field, int& value) {
    if (!Skipped(field)) OnField(field, value);
  }
  void Visit(const OptionField& field, double& value) {
    if (!Skipped(field)) OnField(field, value);
  }
  void Visit(const OptionField& field, bool& value) {
    if (!Skipped(field)) OnField(field, value);
  }
  void Visit(const OptionField& field, std::string& value) {
    if (!Skipped(field)) OnField(field, value);
  }
  void Visit(const OptionField& field, std::vector<int>& value) {
    if (!Skipped(field)) OnField(field, value);
  }
  // A number that may be unset: "the default follows another option" (the build's tau: the matcher's).
  void Visit(const OptionField& field, std::optional<double>& value) {
    if (!Skipped(field)) OnField(field, value);
  }
  void Visit(const OptionField& field, const EnumField& value) {
    if (!Skipped(field)) OnField(field, value);
  }

  // Visits the fields of `options`, the field `name` of the struct being visited ("" adds no level: a struct
  // visited as the top).
  template <typename Options>
  void VisitNested(const char* name, Options& options, const Nesting& nesting = {}) {
    if (Skipped(name)) return;
    // A section begun inside a nested struct ends with it; one that does not begin any goes on in its holder's.
    const std::string holder_section = section_;
    if (*name == '\0' && nesting.skip.empty()) {
      options.VisitFields(*this);
    } else {
      levels_.push_back({name, nesting});
      OnEnter(name, nesting.json_inline || *name == '\0');
      options.VisitFields(*this);
      OnLeave(nesting.json_inline || *name == '\0');
      levels_.pop_back();
    }
    section_ = holder_section;
  }

  // The fields visited after this, up to the next Section or the end of the struct, belong to a section titled
  // `title` ("Acceptance: when a frame is at a key image"): a command's --help lists its flags under such headings.
  // Only the flag binder reads it; JSON and keywords do not depend on it.
  void Section(std::string title) { section_ = std::move(title); }
  const std::string& section() const { return section_; }  // "": none (a command's plain "Options")

  // The field's path from the struct visited first: "link_analysis.pose.threshold".
  std::string Path(const OptionField& field) const {
    std::string path;
    for (const Level& level : levels_) {
      if (*level.name != '\0') path += std::string(level.name) + ".";
    }
    return path + field.path_name();
  }

 protected:
  virtual void OnField(const OptionField& field, int& value) = 0;
  virtual void OnField(const OptionField& field, double& value) = 0;
  virtual void OnField(const OptionField& field, bool& value) = 0;
  virtual void OnField(const OptionField& field, std::string& value) = 0;
  virtual void OnField(const OptionField& field, std::vector<int>& value) = 0;
  virtual void OnField(const OptionField& field, const EnumField& value) = 0;
  // Visitors of structs without such a field need not take one.
  virtual void OnField(const OptionField& field, std::optional<double>& /*value*/) {
    throw std::logic_error(std::string("option ") + field.key + ": this visitor takes no optional number");
  }
  // Around a nested struct's fields; `json_inline`: its fields belong to the holder's JSON object.
  virtual void OnEnter(const char* /*name*/, bool /*json_inline*/) {}
  virtual void OnLeave(bool /*json_inline*/) {}

 private:
  struct Level {
    const char* name;
    Nesting nesting;
  };

  bool Skipped(const OptionField& field) const { return Skipped(field.key); }
  bool Skipped(const char* key) const {
    if (levels_.empty() || *key == '\0') return false;
    for (const char* skipped : levels_.back().nesting.skip) {
      if (std::strcmp(skipped, key) == 0) return true;
    }
    return false;
  }

  std::vector<Level> levels_;
  std::string section_;
};

}  // namespace vmap
