#pragma once
// vmap's options as ROS parameters. Every field of an options struct that has a command-line flag is a private
// parameter of the node named after the flag, its dashes as underscores (--min-link-share: ~min_link_share,
// --no-step-back: ~no_step_back), with the flag's default: a parameter that is not set keeps the field as it is.
// The fields are read through their field lists (core/option_fields.h), as the CLI binds its flags, so the node
// knows no option of its own.

#include <map>
#include <optional>
#include <set>
#include <string>

#include <ros/node_handle.h>

#include "vmap/core/error.h"
#include "vmap/core/option_fields.h"

namespace vmap::ros_node {

// The parameter of a flag: "--min-link-share" -> "min_link_share", "!--no-step-back" -> "no_step_back",
// "-t,--tau" -> "tau"; "" for a field without a flag or a positional argument.
std::string ParameterName(const char* flag);

class ParameterReader final : public OptionFieldVisitor {
 public:
  // Reads from `node`'s parameters (the node's private handle, "~").
  explicit ParameterReader(const ros::NodeHandle& node) : node_(node) {}

  // Reads the fields of `options` that have a parameter set. Throws InputError naming the parameter when a value
  // is of the wrong kind (a string for a number) or not one of an enum's names.
  template <typename Options>
  void Read(Options& options) {
    options.VisitFields(*this);
  }

  // The paths of the fields read from a parameter that was set ("min_link_share", "ranking.method").
  const std::set<std::string>& given() const { return given_; }
  // `error`, an OptionError of a struct read here, as the parameters name its field ("~min_link_share must be
  // ..."); other errors as they are.
  std::string Message(const InputError& error) const;

 protected:
  void OnField(const OptionField& field, int& value) override;
  void OnField(const OptionField& field, double& value) override;
  void OnField(const OptionField& field, std::optional<double>& value) override;
  void OnField(const OptionField& field, bool& value) override;
  void OnField(const OptionField& field, std::string& value) override;
  void OnField(const OptionField& field, std::vector<int>& value) override;
  void OnField(const OptionField& field, const EnumField& value) override;

 private:
  // The field's parameter when it has one and it is set (and notes it); "" otherwise.
  std::string SetParameter(const OptionField& field);

  ros::NodeHandle node_;
  std::set<std::string> given_;
  std::map<std::string, std::string> parameter_of_path_;
};

// The parameters of `Options`' fields (those with a flag).
class ParameterNames final : public OptionFieldVisitor {
 public:
  template <typename Options>
  void Add(Options& options) {
    options.VisitFields(*this);
  }
  const std::set<std::string>& names() const { return names_; }

 protected:
  void OnField(const OptionField& field, int&) override { Note(field); }
  void OnField(const OptionField& field, double&) override { Note(field); }
  void OnField(const OptionField& field, std::optional<double>&) override { Note(field); }
  void OnField(const OptionField& field, bool&) override { Note(field); }
  void OnField(const OptionField& field, std::string&) override { Note(field); }
  void OnField(const OptionField& field, std::vector<int>&) override { Note(field); }
  void OnField(const OptionField& field, const EnumField&) override { Note(field); }

 private:
  void Note(const OptionField& field) {
    const std::string name = ParameterName(field.flag);
    if (!name.empty()) names_.insert(name);
  }
  std::set<std::string> names_;
};

// Logs a warning for each private parameter of `node` that is not in `known` (the fields' parameters and the
// node's own): most likely a typo, which would otherwise leave an option at its default unnoticed.
void WarnAboutUnknownParameters(const ros::NodeHandle& node, const std::set<std::string>& known);

}  // namespace vmap::ros_node
