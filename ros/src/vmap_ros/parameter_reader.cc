#include "vmap_ros/parameter_reader.h"

#include <cmath>
#include <limits>
#include <vector>

#include <ros/console.h>
#include <ros/param.h>
#include <xmlrpcpp/XmlRpcValue.h>

namespace vmap::ros_node {
namespace {

std::string KindOf(XmlRpc::XmlRpcValue& value) {
  switch (value.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean:
      return "a boolean";
    case XmlRpc::XmlRpcValue::TypeInt:
      return "an integer";
    case XmlRpc::XmlRpcValue::TypeDouble:
      return "a number";
    case XmlRpc::XmlRpcValue::TypeString:
      return "a string";
    case XmlRpc::XmlRpcValue::TypeArray:
      return "a list";
    case XmlRpc::XmlRpcValue::TypeStruct:
      return "a dictionary";
    default:
      return "a value of another kind";
  }
}

InputError WrongKind(const std::string& parameter, XmlRpc::XmlRpcValue& value, const std::string& wanted) {
  return InputError("parameter ~" + parameter + " is " + KindOf(value) + "; it must be " + wanted);
}

}  // namespace

std::string ParameterName(const char* flag) {
  std::string name = flag;
  if (!name.empty() && name[0] == '!') name.erase(0, 1);
  if (name.empty() || name[0] != '-') return "";  // a positional argument (the input), not an option
  // "-t,--tau": the long name.
  const size_t comma = name.rfind(',');
  if (comma != std::string::npos) name.erase(0, comma + 1);
  while (!name.empty() && name[0] == '-') name.erase(0, 1);
  for (char& c : name) {
    if (c == '-') c = '_';
  }
  return name;
}

std::string ParameterReader::SetParameter(const OptionField& field) {
  const std::string name = ParameterName(field.flag);
  if (name.empty()) return "";
  parameter_of_path_[Path(field)] = name;
  if (!node_.hasParam(name)) return "";
  given_.insert(Path(field));
  return name;
}

void ParameterReader::OnField(const OptionField& field, int& value) {
  const std::string name = SetParameter(field);
  if (name.empty()) return;
  XmlRpc::XmlRpcValue v;
  node_.getParam(name, v);
  if (v.getType() != XmlRpc::XmlRpcValue::TypeInt) throw WrongKind(name, v, "an integer");
  value = static_cast<int>(v);
}

void ParameterReader::OnField(const OptionField& field, double& value) {
  const std::string name = SetParameter(field);
  if (name.empty()) return;
  XmlRpc::XmlRpcValue v;
  node_.getParam(name, v);
  if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) {
    value = static_cast<int>(v);
  } else if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) {
    value = static_cast<double>(v);
  } else {
    throw WrongKind(name, v, "a number");
  }
}

void ParameterReader::OnField(const OptionField& field, std::optional<double>& value) {
  double number = value.value_or(0.0);
  const std::string name = ParameterName(field.flag);
  OnField(field, number);
  if (!name.empty() && node_.hasParam(name)) value = number;
}

void ParameterReader::OnField(const OptionField& field, bool& value) {
  const std::string name = SetParameter(field);
  if (name.empty()) return;
  XmlRpc::XmlRpcValue v;
  node_.getParam(name, v);
  if (v.getType() != XmlRpc::XmlRpcValue::TypeBoolean) throw WrongKind(name, v, "true or false");
  // "!--no-x" sets the field false: ~no_x true does.
  const bool negated = field.flag[0] == '!';
  value = static_cast<bool>(v) != negated;
}

void ParameterReader::OnField(const OptionField& field, std::string& value) {
  const std::string name = SetParameter(field);
  if (name.empty()) return;
  XmlRpc::XmlRpcValue v;
  node_.getParam(name, v);
  // YAML reads `resize: 640` as a number: the flag takes it as text.
  if (v.getType() == XmlRpc::XmlRpcValue::TypeString) {
    value = static_cast<std::string>(v);
  } else if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) {
    value = std::to_string(static_cast<int>(v));
  } else {
    throw WrongKind(name, v, "a string");
  }
}

void ParameterReader::OnField(const OptionField& field, std::vector<int>& value) {
  const std::string name = SetParameter(field);
  if (name.empty()) return;
  XmlRpc::XmlRpcValue v;
  node_.getParam(name, v);
  if (v.getType() != XmlRpc::XmlRpcValue::TypeArray) throw WrongKind(name, v, "a list of integers");
  std::vector<int> list;
  for (int i = 0; i < v.size(); ++i) {
    if (v[i].getType() != XmlRpc::XmlRpcValue::TypeInt) throw WrongKind(name, v[i], "a list of integers");
    list.push_back(static_cast<int>(v[i]));
  }
  value = std::move(list);
}

void ParameterReader::OnField(const OptionField& field, const EnumField& value) {
  const std::string name = SetParameter(field);
  if (name.empty()) return;
  XmlRpc::XmlRpcValue v;
  node_.getParam(name, v);
  if (v.getType() != XmlRpc::XmlRpcValue::TypeString) throw WrongKind(name, v, value.names());
  try {
    value.Parse(static_cast<std::string>(v));
  } catch (const InputError& error) {
    throw InputError("parameter ~" + name + ": " + error.what());
  }
}

std::string ParameterReader::Message(const InputError& error) const {
  const auto* option = dynamic_cast<const OptionError*>(&error);
  if (option == nullptr) return error.what();
  const auto found = parameter_of_path_.find(option->path());
  if (found == parameter_of_path_.end()) return error.what();
  std::string message = "~" + found->second + " " + option->problem();
  // Other fields the problem names, by their last component, as parameters.
  for (const std::string& other : option->others()) {
    const auto parameter = parameter_of_path_.find(other);
    if (parameter == parameter_of_path_.end()) continue;
    const std::string last = other.substr(other.rfind('.') + 1);
    const size_t at = message.find(last, found->second.size() + 2);
    if (at != std::string::npos) message.replace(at, last.size(), "~" + parameter->second);
  }
  return message;
}

void WarnAboutUnknownParameters(const ros::NodeHandle& node, const std::set<std::string>& known) {
  std::vector<std::string> names;
  if (!ros::param::getParamNames(names)) return;
  const std::string prefix = node.getNamespace() + "/";
  for (const std::string& full : names) {
    if (full.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string name = full.substr(prefix.size());
    if (name.find('/') != std::string::npos) continue;  // a namespace of its own (image_transport's, ...)
    if (known.count(name) == 0) {
      ROS_WARN("parameter ~%s is none of vmap's; it is ignored (a typo? docs/ros.md lists the parameters)",
               name.c_str());
    }
  }
}

}  // namespace vmap::ros_node
