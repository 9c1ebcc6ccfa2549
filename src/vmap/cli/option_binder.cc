#include "vmap/cli/option_binder.h"

#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "vmap/core/error.h"
#include "vmap/core/option_ranges.h"

namespace vmap::cli {

namespace {

std::string Help(const OptionField& field, const std::string& names) {
  return field.lists_names ? field.help + names : field.help;
}

CLI::Option* BindEnum(CLI::App* command, const std::string& flag, const OptionField& field,
                      const std::vector<EnumField>& values) {
  return command
      ->add_option_function<std::string>(
          flag,
          [values, flag](const std::string& text) {
            try {
              for (const EnumField& value : values) value.Parse(text);
            } catch (const InputError& error) {
              // Named as a number flag's error is ("--law: unknown control law 'TRACKER'; use ...").
              throw InputError(flag.substr(flag.rfind(',') + 1) + ": " + error.what());
            }
          },
          Help(field, values.front().names()))
      ->default_str(values.front().name());
}

template <typename T>
CLI::Option* BindValues(CLI::App* command, const std::string& flag, const OptionField& field,
                        const std::vector<T*>& values) {
  if constexpr (std::is_same_v<T, bool>) {
    // A switch; "!--no-x" sets false. Several fields that share it are each set.
    const bool negated = flag.front() == '!';
    if (values.size() == 1) return command->add_flag(flag, *values.front(), field.help);
    return command->add_flag_function(
        negated ? flag.substr(1) : flag,
        [values, negated](std::int64_t count) {
          for (bool* value : values) *value = (count > 0) != negated;
        },
        field.help);
  }
  if (flag.front() == '!') throw std::logic_error("flag " + flag + ": a negated flag needs bool fields");
  CLI::Option* option = nullptr;
  if (values.size() == 1) {
    option = command->add_option(flag, *values.front(), field.help);
    if (field.show_default && !field.positional) option->capture_default_str();
  } else {
    option = command->add_option_function<T>(
        flag,
        [values](const T& value) {
          for (T* f : values) *f = value;
        },
        field.help);
    if (field.show_default && !field.positional) {
      std::ostringstream text;
      text << std::boolalpha << *values.front();
      option->default_str(text.str());
    }
  }
  // A positional argument (its flag is its name) is required.
  return field.positional ? option->required() : option;
}

}  // namespace

std::string TypeWithValues(const std::string& type, const OptionRange& range, bool integral) {
  if (!range.is_set) return type;
  return type + (range.also ? " " : " in ") + RangeText(range, integral);
}

void OptionBinder::OnField(const OptionField& field, std::vector<int>& /*value*/) {
  if (*field.flag != '\0') throw std::logic_error(std::string("flag ") + field.flag + ": a list field has no flag");
}

void OptionBinder::AddTarget(const OptionField& field, Target value) {
  if (*field.flag == '\0') return;
  auto [it, added] = flags_.try_emplace(field.flag, Targets{field, {}, {}, section()});
  if (added) order_.push_back(field.flag);
  Targets& targets = it->second;
  if (!targets.values.empty() && targets.values.front().index() != value.index()) {
    throw std::logic_error(std::string("flag ") + field.flag + " has fields of different types");
  }
  if (!targets.values.empty() && std::holds_alternative<EnumField>(value) &&
      std::get<EnumField>(targets.values.front()).names() != std::get<EnumField>(value).names()) {
    throw std::logic_error(std::string("flag ") + field.flag + " has fields of different enums");
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
          if constexpr (std::is_same_v<T, std::optional<double>*>) {
            // Unset until given: no default to show (the help says what it follows).
            if (targets.values.size() != 1) throw std::logic_error("flag " + flag + ": an optional field shares it");
            std::optional<double>* value = first;
            return command->add_option_function<double>(
                flag, [value](double given) { *value = given; }, targets.field.help);
          } else if constexpr (std::is_same_v<T, EnumField>) {
            std::vector<EnumField> values;
            for (const Target& target : targets.values) values.push_back(std::get<EnumField>(target));
            return BindEnum(command, flag, targets.field, values);
          } else {
            using Value = std::remove_pointer_t<T>;
            std::vector<Value*> values;
            for (const Target& target : targets.values) values.push_back(std::get<T>(target));
            CLI::Option* option = BindValues(command, flag, targets.field, values);
            if constexpr (std::is_same_v<Value, int> || std::is_same_v<Value, double>) {
              // CLI11 answers "abc", "1.5" or "2147483648" with "Could not convert"; say what the flag takes instead.
              // The text is read by CLI11's own conversion, so every spelling it accepts still passes.
              const OptionRange& range = targets.field.range;
              const std::string values = range.is_set ? RangeText(range, std::is_same_v<Value, int>) : "";
              const std::string takes = std::string(std::is_same_v<Value, int> ? "an integer" : "a number") +
                                        (!range.is_set ? "" : (range.also ? ": " : " in ") + values);
              option->check(CLI::Validator(
                  [takes](std::string& text) -> std::string {
                    Value parsed{};
                    return CLI::detail::lexical_cast(text, parsed) ? "" : text + " is not " + takes;
                  },
                  ""));
              option->type_name(TypeWithValues(option->get_type_name(), range, std::is_same_v<Value, int>));
            }
            return option;
          }
        },
        targets.values.front());
    if (!targets.section.empty()) option->group(targets.section);
    for (const std::string& path : targets.paths) option_flags.Record(path, option);
  }
}

}  // namespace vmap::cli
