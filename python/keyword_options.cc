#include "keyword_options.h"

#include <algorithm>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

#include "vmap/core/option_names.h"
#include "vmap/core/option_ranges.h"

#include "argument_errors.h"

namespace py = pybind11;

namespace vmap::python {

namespace {

// The keywords of a flag: "--max-iters" is max_iters, "!--no-cache" no_cache (negated); short names and
// positional arguments have none.
std::vector<std::string> FlagKeywords(std::string flag, bool* negated) {
  *negated = !flag.empty() && flag.front() == '!';
  if (*negated) flag.erase(0, 1);
  std::vector<std::string> keywords;
  size_t start = 0;
  while (start <= flag.size()) {
    const size_t comma = std::min(flag.find(',', start), flag.size());
    const std::string name = flag.substr(start, comma - start);
    if (name.rfind("--", 0) == 0) {
      std::string keyword = name.substr(2);
      std::replace(keyword.begin(), keyword.end(), '-', '_');
      keywords.push_back(keyword);
    }
    start = comma + 1;
  }
  return keywords;
}

bool IsOption(const OptionField& field) { return field.flag[0] == '-' || field.flag[0] == '!'; }

// "int in [1, 2]", "float 0 or [1, 1000]": the type and the values the field takes, as --help gives them.
std::string NumberType(const OptionField& field, bool integral) {
  const std::string type = integral ? "int" : "float";
  if (!field.range.is_set) return type;
  return type + (field.range.also ? " " : " in ") + RangeText(field.range, integral);
}

std::string QuotedText(const std::string& text) { return "'" + text + "'"; }

}  // namespace

void KeywordOptions::OnEnter(const char* name, bool json_inline) { prefixes_.push_back(json_inline ? "" : name); }

void KeywordOptions::OnLeave(bool /*json_inline*/) { prefixes_.pop_back(); }

void KeywordOptions::OnField(const OptionField& field, int& value) {
  AddField(field, documenting_ ? Described{NumberType(field, true), std::to_string(value)} : Described{},
           [&value](const py::handle& v, const std::string& what) { value = IntArgument(v, what); });
}

void KeywordOptions::OnField(const OptionField& field, double& value) {
  AddField(field, documenting_ ? Described{NumberType(field, false), fmt::format("{}", value)} : Described{},
           [&value](const py::handle& v, const std::string& what) { value = FloatArgument(v, what); });
}

void KeywordOptions::OnField(const OptionField& field, bool& value) {
  AddField(
      field, documenting_ ? Described{"bool", value ? "True" : "False"} : Described{},
      [&value](const py::handle& v, const std::string& what) { value = BoolArgument(v, what); },
      [&value](bool on) { value = on; });
}

void KeywordOptions::OnField(const OptionField& field, std::optional<double>& value) {
  AddField(field,
           documenting_ ? Described{NumberType(field, false), value ? fmt::format("{}", *value) : "None"} : Described{},
           [&value](const py::handle& v, const std::string& what) { value = FloatArgument(v, what); });
}

void KeywordOptions::OnField(const OptionField& field, std::string& value) {
  AddField(field, documenting_ ? Described{"str", QuotedText(value)} : Described{},
           [&value](const py::handle& v, const std::string& what) { value = TextArgument(v, what); });
}

void KeywordOptions::OnField(const OptionField& field, std::vector<int>& /*value*/) {
  if (IsOption(field)) throw std::logic_error(std::string("option ") + field.key + ": a list field has no keyword");
}

void KeywordOptions::OnField(const OptionField& field, const EnumField& value) {
  AddField(field, documenting_ ? Described{"str", QuotedText(value.name()), value.names()} : Described{},
           [value](const py::handle& v, const std::string& what) {
             if (!PyUnicode_Check(v.ptr()))
               throw ArgumentTypeError(what + " takes a str (" + value.names() + "), not " + TypeName(v));
             value.Parse(v.cast<std::string>());
           });
}

void KeywordOptions::AddField(const OptionField& field, const Described& described, Setter set,
                              std::function<void(bool)> set_bool) {
  if (!IsOption(field)) return;  // no flag, or a positional argument: not an option a call takes by keyword
  std::string keyword;
  for (const std::string& prefix : prefixes_) {
    if (!prefix.empty()) keyword += prefix + "_";
  }
  keyword += field.path_name();
  bool negated = false;
  const std::vector<std::string> aliases = FlagKeywords(field.flag, &negated);
  Field entry{keyword, Path(field), std::move(set), std::move(set_bool)};
  if (documenting_) {
    // The docstring's line: a negated flag's help says what its keyword does, so that keyword stands for the field.
    entry.section = section();
    if (negated && !aliases.empty()) {
      entry.signature = aliases.front() + ": bool = " + (described.value == "True" ? "False" : "True") +
                        " (the opposite of " + keyword + ")";
    } else {
      // A default the help describes ("default: the first") is None's, what keeps it.
      entry.signature = keyword + ": " + described.type + " = " + (field.show_default ? described.value : "None");
      if (!aliases.empty() && aliases.front() != keyword) entry.signature += " (or " + aliases.front() + "=)";
    }
    entry.help = field.help + (field.lists_names ? described.names : "");
  }
  fields_.push_back(std::move(entry));
  const size_t index = fields_.size() - 1;
  AddKeyword(keyword, index, false);
  for (const std::string& alias : aliases) {
    if (negated && !fields_[index].set_bool) throw std::logic_error("flag " + std::string(field.flag) + " is no bool");
    AddKeyword(alias, index, negated);
  }
}

void KeywordOptions::AddKeyword(const std::string& keyword, size_t field, bool negated) {
  Keyword& entry = keywords_[keyword];
  if (std::find(entry.fields.begin(), entry.fields.end(), field) != entry.fields.end()) return;
  // A keyword names several fields only as a flag they share does (--weights): same negation, a field each.
  if (!entry.fields.empty() && (entry.negated != negated || fields_[entry.fields.front()].keyword == keyword ||
                                fields_[field].keyword == keyword)) {
    throw std::logic_error("keyword " + keyword + " names two options: " + fields_[entry.fields.front()].path +
                           " and " + fields_[field].path);
  }
  entry.negated = negated;
  entry.fields.push_back(field);
}

std::vector<std::string> KeywordOptions::Keywords() const {
  std::vector<std::string> keywords;
  for (const auto& [keyword, entry] : keywords_) keywords.push_back(keyword);
  return keywords;  // a std::map's keys: sorted
}

std::string KeywordOptions::Documentation() const {
  if (!documenting_) throw std::logic_error("KeywordOptions::Documentation needs a documenting KeywordOptions");
  // The sections in the order each first appears, the fields in each in the order visited: --help's layout.
  std::vector<std::string> sections;
  for (const Field& field : fields_) {
    if (std::find(sections.begin(), sections.end(), field.section) == sections.end()) sections.push_back(field.section);
  }
  std::ostringstream text;
  for (const std::string& section : sections) {
    text << "\n" << (section.empty() ? "Options" : section) << ":\n";
    for (const Field& field : fields_) {
      if (field.section != section) continue;
      text << "    " << field.signature << "\n";
      if (!field.help.empty()) text << "        " << field.help << "\n";
    }
  }
  return text.str();
}

void KeywordOptions::Parse(const py::kwargs& kwargs) {
  std::map<size_t, std::string> set_by;  // field -> the keyword that set it
  for (const auto& [key, value] : kwargs) {
    const std::string keyword = key.cast<std::string>();
    const auto found = keywords_.find(keyword);
    if (found == keywords_.end()) {
      std::string names;
      for (const std::string& name : Keywords()) names += (names.empty() ? "" : ", ") + name;
      throw py::type_error(function_ + "() got an unexpected keyword argument '" + keyword + "'; valid: " + names);
    }
    if (value.is_none()) continue;
    const Keyword& entry = found->second;
    const std::string what = function_ + "(): " + keyword;
    for (const size_t index : entry.fields) {
      const auto [earlier, added] = set_by.emplace(index, keyword);
      if (!added) {
        throw py::type_error(function_ + "() got " + earlier->second + " and " + keyword + ", one option twice");
      }
      const Field& field = fields_[index];
      if (entry.negated) {
        field.set_bool(!BoolArgument(value, what));
      } else {
        field.set(value, what);
      }
      given_.push_back(field.path);
    }
  }
}

std::string KeywordOptions::KeywordOf(const std::string& path) const {
  for (const Field& field : fields_) {
    if (field.path == path) return field.keyword;
  }
  return "";
}

void KeywordOptions::Run(const std::function<void()>& work) const {
  try {
    work();
  } catch (const OptionError& error) {
    throw InputError(OptionErrorMessage(error, [this](const std::string& path) { return KeywordOf(path); }));
  }
}

}  // namespace vmap::python
