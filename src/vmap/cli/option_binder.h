#pragma once
// The command-line flags of an options struct, derived from its field list (core/option_fields.h): each field
// with a flag is bound straight onto the struct and recorded in OptionFlags by its path, so that an
// OptionError from Check() reaches the user in the flag's words.

#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <CLI/CLI.hpp>

#include "vmap/cli/option_flags.h"
#include "vmap/core/option_fields.h"

namespace vmap::cli {

// Collects the fields by flag, then binds each flag once (Bind): a flag several fields share (the matchers'
// --weights, --device) sets each of them. Flags come in the order the fields are first visited, under the heading
// of the section their first field was visited in (OptionFieldVisitor::Section; CLI11's option groups, which
// --help lists in the order each first appears).
class OptionBinder final : public OptionFieldVisitor {
 public:
  // Every field of `options` under `path` ("verifier"; "" for the struct the command checks).
  template <typename Options>
  void Add(const char* path, Options& options, const Nesting& nesting = {}) {
    VisitNested(path, options, nesting);
  }
  void Bind(CLI::App* command, OptionFlags& option_flags) const;

 protected:
  void OnField(const OptionField& field, int& value) override { AddTarget(field, &value); }
  void OnField(const OptionField& field, double& value) override { AddTarget(field, &value); }
  void OnField(const OptionField& field, bool& value) override { AddTarget(field, &value); }
  void OnField(const OptionField& field, std::string& value) override { AddTarget(field, &value); }
  void OnField(const OptionField& field, std::vector<int>& value) override;
  void OnField(const OptionField& field, const EnumField& value) override { AddTarget(field, value); }
  void OnField(const OptionField& field, std::optional<double>& value) override { AddTarget(field, &value); }

 private:
  using Target = std::variant<int*, double*, bool*, std::string*, EnumField, std::optional<double>*>;
  struct Targets {
    OptionField field;
    std::vector<Target> values;
    std::vector<std::string> paths;  // of each value
    std::string section;             // the --help heading it is listed under; "" = the command's "Options"
  };

  void AddTarget(const OptionField& field, Target value);

  std::map<std::string, Targets> flags_;
  std::vector<std::string> order_;  // as first visited
};

// A numeric flag's type and the values its field takes, as its --help shows them: "INT in [1, 2]",
// "FLOAT 0 or [1, 1000]"; the type alone where the field declares no range.
std::string TypeWithValues(const std::string& type, const OptionRange& range, bool integral);

// Binds the flags of every field of `options` (see OptionBinder::Add).
template <typename Options>
void AddOptionFlags(CLI::App* command, Options& options, OptionFlags& option_flags, const char* path = "",
                    const Nesting& nesting = {}) {
  OptionBinder binder;
  binder.Add(path, options, nesting);
  binder.Bind(command, option_flags);
}

}  // namespace vmap::cli
