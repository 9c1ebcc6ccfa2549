#include "keyword_options.h"

#include <algorithm>
#include <cctype>

#include "vmap/core/error.h"

namespace py = pybind11;

namespace vmap::python {

namespace {

std::string KeywordOf(const std::string& long_name) {
  std::string keyword = long_name;
  std::replace(keyword.begin(), keyword.end(), '-', '_');
  return keyword;
}

// The value as the command line would spell it; a float by repr, which reads back as the same double.
std::string FlagText(const py::handle& value) {
  if (py::isinstance<py::bool_>(value)) return value.cast<bool>() ? "true" : "false";
  if (py::isinstance<py::int_>(value)) return py::str(value).cast<std::string>();
  if (py::isinstance<py::float_>(value)) return py::repr(value).cast<std::string>();
  if (py::isinstance<py::str>(value)) return value.cast<std::string>();
  if (py::hasattr(value, "__fspath__")) return py::str(value.attr("__fspath__")()).cast<std::string>();
  throw py::type_error("a " + py::str(py::type::of(value).attr("__name__")).cast<std::string>() +
                       " where a number, a string or a bool is expected");
}

}  // namespace

KeywordOptions::KeywordOptions(std::string function) : function_(std::move(function)) {
  command_.set_help_flag();  // no --help keyword
  command_.allow_extras(false);
}

std::vector<std::string> KeywordOptions::Keywords() const {
  std::vector<std::string> keywords;
  for (const CLI::Option* option : command_.get_options()) {
    for (const std::string& name : option->get_lnames()) keywords.push_back(KeywordOf(name));
  }
  std::sort(keywords.begin(), keywords.end());
  return keywords;
}

void KeywordOptions::Parse(const py::kwargs& kwargs) {
  std::vector<std::string> args;
  for (const auto& [key, value] : kwargs) {
    const std::string keyword = key.cast<std::string>();
    const CLI::Option* found = nullptr;
    std::string flag;
    for (const CLI::Option* option : command_.get_options()) {
      for (const std::string& name : option->get_lnames()) {
        if (KeywordOf(name) == keyword) found = option, flag = "--" + name;
      }
    }
    if (!found) {
      std::string names;
      for (const std::string& name : Keywords()) names += (names.empty() ? "" : ", ") + name;
      throw py::type_error(function_ + "() got an unexpected keyword argument '" + keyword + "'; valid: " + names);
    }
    if (value.is_none()) continue;
    if (found->get_expected_max() == 0) {  // a flag: on or off
      if (!py::isinstance<py::bool_>(value)) throw py::type_error(keyword + " takes True or False");
      if (value.cast<bool>()) args.push_back(flag);
      continue;
    }
    try {
      args.push_back(flag + "=" + FlagText(value));
    } catch (const py::type_error& e) {
      throw py::type_error(function_ + "(): " + keyword + " got " + e.what());
    }
  }
  std::reverse(args.begin(), args.end());  // CLI11 takes them last first
  try {
    Run([&] { command_.parse(args); });
  } catch (const CLI::ParseError& e) {
    throw InputError(InKeywords(e.what()));
  }
}

void KeywordOptions::Run(const std::function<void()>& work) const {
  try {
    work();
  } catch (const OptionError& error) {
    throw InputError(InKeywords(option_flags_.Message(error)));
  } catch (const InputError& error) {
    throw InputError(InKeywords(error.what()));
  }
}

std::string KeywordOptions::InKeywords(std::string text) const {
  std::vector<std::string> names;
  for (const CLI::Option* option : command_.get_options()) {
    for (const std::string& name : option->get_lnames()) names.push_back(name);
  }
  // Longest first: --pose-threshold before --pose.
  std::sort(names.begin(), names.end(), [](const std::string& a, const std::string& b) { return a.size() > b.size(); });
  for (const std::string& name : names) {
    const std::string flag = "--" + name;
    for (size_t at = text.find(flag); at != std::string::npos; at = text.find(flag, at + 1)) {
      const size_t end = at + flag.size();
      if (end < text.size() && (std::isalnum(static_cast<unsigned char>(text[end])) || text[end] == '-')) continue;
      text.replace(at, flag.size(), KeywordOf(name));
    }
  }
  return text;
}

}  // namespace vmap::python
