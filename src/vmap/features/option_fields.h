#pragma once
// One field list per matcher model's options, from which its JSON (map.json's options.matcher) and its
// command-line flags are derived. An options struct lists its fields once:
//
//   void VisitFields(OptionFieldVisitor& visitor) {
//     visitor.Visit({"num_features", "--orb-features", "ORB: features per image"}, num_features);
//     ...
//   }
//
// Readers and writers (JSON here, CLI11 in cli/) are visitors; none of them knows the model.

#include <string>

namespace vmap {

struct OptionField {
  const char* key;         // the name in JSON
  const char* flag = "";   // the command-line flag; "" = none. "!--no-x" is a bool flag that sets false.
                           // Models may share a flag (--weights, --device): it then sets the field of each.
  const char* help = "";   // the flag's help
  bool show_default = true;  // --help shows the default (off where the default means "the preset's")
  // A file recorded where a map was built (weights): when a map read on another machine names a file that is
  // not here, it is cleared, so that the model searches its weights directories instead.
  bool is_local_file = false;
};

class OptionFieldVisitor {
 public:
  virtual ~OptionFieldVisitor() = default;
  virtual void Visit(const OptionField& field, int& value) = 0;
  virtual void Visit(const OptionField& field, double& value) = 0;
  virtual void Visit(const OptionField& field, bool& value) = 0;
  virtual void Visit(const OptionField& field, std::string& value) = 0;
};

}  // namespace vmap
