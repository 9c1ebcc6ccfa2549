#pragma once
// Python keyword arguments bound to an options struct through its field list (core/option_fields.h), by field,
// with typed values: the keyword `verifier_threshold` sets the field VerifierOptions::threshold of the struct
// the call takes, as a float, its type checked. Keywords are the fields' names: a field's JSON key, after the
// names of the structs that hold it where its record nests them (`tau`, `verifier_max_iterations`,
// `orb_num_features`, `heading_window_px`). Where the CLI's flag says it otherwise, the flag's name is a keyword
// too (`max_iters`, `orb_features`, `heading_window`, `threshold`, `no_cache=True` for `cache=False`), so that
// scripts written with the flags' names keep working. The options a call takes are the fields with a flag: the
// ones a user sets.

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/pybind11.h>

#include "vmap/core/error.h"
#include "vmap/core/option_fields.h"

namespace vmap::python {

class KeywordOptions final : public OptionFieldVisitor {
 public:
  // `function`: the Python function's name, for messages ("build_map"). `documenting`: also keep each field's line
  // for Documentation() (KeywordDocstring, once when the module loads); a call's parsing skips that work.
  explicit KeywordOptions(std::string function, bool documenting = false)
      : function_(std::move(function)), documenting_(documenting) {}

  // The fields of `options` (a struct with VisitFields), but those whose key is in `skip` (the call's positional
  // arguments, a front end's own options). `options` must outlive Parse.
  template <typename Options>
  void Add(Options& options, std::vector<const char*> skip = {}) {
    VisitNested("", options, Nesting{false, std::move(skip)});
  }

  // Sets the fields from `kwargs` (None keeps a default), each value converted with its type checked: a value of
  // the wrong type is a vmap.ArgumentTypeError (a TypeError and a vmap.Error), an unknown keyword a TypeError
  // listing the valid ones. Call with the GIL held.
  void Parse(const pybind11::kwargs& kwargs);

  // The keywords accepted (fields' names and flags' names), sorted.
  std::vector<std::string> Keywords() const;
  // The keywords for a docstring, under the headings of the command's --help (OptionFieldVisitor::Section), in
  // its order: "name: type = default" (the flag's name after "or" where it differs), then the flag's help. A
  // negated flag's field is given by the flag's keyword (no_cache: bool = False), which its help describes.
  // Needs `documenting`.
  std::string Documentation() const;
  // The paths of the fields Parse set ("min_verified"), for the checks of what was given.
  const std::vector<std::string>& Given() const { return given_; }

  // Runs `work`; an OptionError from it comes out as an InputError naming the fields by their keywords.
  void Run(const std::function<void()>& work) const;

 protected:
  void OnField(const OptionField& field, int& value) override;
  void OnField(const OptionField& field, double& value) override;
  void OnField(const OptionField& field, bool& value) override;
  void OnField(const OptionField& field, std::string& value) override;
  void OnField(const OptionField& field, std::vector<int>& value) override;
  void OnField(const OptionField& field, const EnumField& value) override;
  void OnField(const OptionField& field, std::optional<double>& value) override;
  void OnEnter(const char* name, bool json_inline) override;
  void OnLeave(bool json_inline) override;

 private:
  // Converts a Python value and sets the field; `what` names the keyword for messages.
  using Setter = std::function<void(const pybind11::handle& value, const std::string& what)>;
  struct Field {
    std::string keyword;  // its name
    std::string path;     // as its checks name it
    Setter set;
    std::function<void(bool)> set_bool;  // bool fields: for the negated flag's keyword (no_cache=True)
    // For Documentation(): the section, "name: type = default" (what the call takes), the flag's help.
    std::string section;
    std::string signature;
    std::string help;
  };
  // How a field's value reads in a docstring: its Python type (with the values it takes) and its default.
  struct Described {
    std::string type;
    std::string value;
    std::string names = {};  // an enum's: "a, b or c", which a help that lists them ends with
  };
  struct Keyword {
    std::vector<size_t> fields;  // indices into fields_ (a flag several fields share sets each)
    bool negated = false;        // the keyword of a "!--no-x" flag: True sets the field false
  };

  void AddField(const OptionField& field, const Described& described, Setter set,
                std::function<void(bool)> set_bool = {});
  void AddKeyword(const std::string& keyword, size_t field, bool negated);
  std::string KeywordOf(const std::string& path) const;  // "" when no field has it

  std::string function_;
  bool documenting_ = false;
  std::vector<Field> fields_;
  std::map<std::string, Keyword> keywords_;
  std::vector<std::string> prefixes_;  // of the structs entered: their names where their record nests them
  std::vector<std::string> given_;
};

// A docstring: `summary`, then the keywords a function takes from a default `Options` (but `skip`), by section
// (KeywordOptions::Documentation), so that help(vmap.localize) lists what `vmap localize --help` does.
template <typename Options>
std::string KeywordDocstring(const std::string& summary, std::vector<const char*> skip = {}) {
  Options options;
  KeywordOptions keywords("", /*documenting=*/true);
  keywords.Add(options, std::move(skip));
  return summary + "\n\nKeywords (None keeps the default):\n" + keywords.Documentation();
}

}  // namespace vmap::python
