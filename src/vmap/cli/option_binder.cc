#include "vmap/cli/option_binder.h"

#include <sstream>
#include <stdexcept>
#include <type_traits>

namespace vmap::cli {

namespace {

std::string Help(const OptionField& field, const std::string& names) {
  return field.lists_names ? field.help + names : field.help;
}

CLI::Option* BindEnum(CLI::App* command, const std::string& flag, const OptionField& field, const EnumField& value) {
  return command
      ->add_option_function<std::string>(
          flag, [value](const std::string& text) { value.Parse(text); }, Help(field, value.names()))
      ->default_str(value.name());
}

template <typename T>
CLI::Option* BindValues(CLI::App* command, const std::string& flag, const OptionField& field,
                        const std::vector<T*>& values) {
  if (flag.front() == '!') {  // "!--no-x": a bool flag that sets false
    if constexpr (std::is_same_v<T, bool>) {
      if (values.size() == 1) return command->add_flag(flag, *values.front(), field.help);
    }
    throw std::logic_error("flag " + flag + ": a negated flag needs exactly one bool field");
  }
  if constexpr (std::is_same_v<T, bool>) {
    if (values.size() == 1) return command->add_flag(flag, *values.front(), field.help);
  }
  CLI::Option* option = nullptr;
  if (values.size() == 1) {
    option = command->add_option(flag, *values.front(), field.help);
    if (field.show_default) option->capture_default_str();
    return option;
  }
  option = command->add_option_function<T>(
      flag,
      [values](const T& value) {
        for (T* f : values) *f = value;
      },
      field.help);
  if (field.show_default) {
    std::ostringstream text;
    text << std::boolalpha << *values.front();
    option->default_str(text.str());
  }
  return option;
}

}  // namespace

void OptionBinder::OnField(const OptionField& field, std::vector<int>& /*value*/) {
  if (*field.flag != '\0') throw std::logic_error(std::string("flag ") + field.flag + ": a list field has no flag");
}

void OptionBinder::AddTarget(const OptionField& field, Target value) {
  if (*field.flag == '\0') return;
  auto [it, added] = flags_.try_emplace(field.flag, Targets{field, {}, {}});
  if (added) order_.push_back(field.flag);
  Targets& targets = it->second;
  if (!targets.values.empty() && targets.values.front().index() != value.index()) {
    throw std::logic_error(std::string("flag ") + field.flag + " has fields of different types");
  }
  if (!targets.values.empty() && std::holds_alternative<EnumField>(value)) {
    throw std::logic_error(std::string("flag ") + field.flag + ": an enum field cannot share its flag");
  }
  targets.values.push_back(std::move(value));
  targets.paths.push_back(Path(field));
}

void OptionBinder::Bind(CLI::App* command, OptionFlags& option_flags) const {
  for (const std::string& flag : order_) {
    const Targets& targets = flags_.at(flag);
    CLI::Option* option = std::visit(
        [&](const auto& first) -> CLI::Option* {
          using T = std::decay_t<decltype(first)>;
          if constexpr (std::is_same_v<T, EnumField>) {
            return BindEnum(command, flag, targets.field, first);
          } else {
            using Value = std::remove_pointer_t<T>;
            std::vector<Value*> values;
            for (const Target& target : targets.values) values.push_back(std::get<T>(target));
            return BindValues(command, flag, targets.field, values);
          }
        },
        targets.values.front());
    for (const std::string& path : targets.paths) option_flags.Record(path, option);
  }
}

}  // namespace vmap::cli
