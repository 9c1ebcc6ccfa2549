#include "vmap/cli/option_flags.h"

#include <algorithm>
#include <regex>
#include <stdexcept>
#include <system_error>

#include "vmap/core/option_names.h"

namespace vmap::cli {

CLI::Option* OptionFlags::Record(const std::string& path, CLI::Option* option) {
  Record(path, option->get_name());
  options_[path] = option;
  return option;
}

void OptionFlags::Record(const std::string& path, const std::string& flag) {
  const auto [it, added] = flags_.emplace(path, flag);
  if (!added && it->second != flag) {
    throw std::logic_error("option field " + path + " has two flags, " + it->second + " and " + flag);
  }
}

std::string OptionFlags::FlagOf(const std::string& path) const {
  const auto it = flags_.find(path);
  return it == flags_.end() ? "" : it->second;
}

std::vector<std::string> OptionFlags::Given() const {
  std::vector<std::string> given;
  for (const auto& [path, option] : options_) {
    if (option->count() > 0) given.push_back(path);
  }
  return given;
}

std::string OptionFlags::Message(const OptionError& error) const {
  return OptionErrorMessage(error, [this](const std::string& path) { return FlagOf(path); });
}

void OptionFlags::Run(const std::function<void()>& run) const {
  try {
    run();
  } catch (const OptionError& error) {
    throw InputError(Message(error));
  }
}

void RefuseEmptyArguments(int argc, const char* const* argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    if (argument == "--") break;
    const size_t equals = argument.find('=');
    if (argument.rfind("--", 0) == 0 && equals != std::string::npos && equals + 1 == argument.size()) {
      throw InputError(argument.substr(0, equals) + " is empty; give it a value or leave it out");
    }
    if (!argument.empty()) continue;
    const std::string previous = i > 1 ? argv[i - 1] : "";
    if (previous.size() > 1 && previous[0] == '-' && previous.find('=') == std::string::npos) {
      throw InputError(previous + " is empty; give it a value or leave it out");
    }
    throw InputError("argument " + std::to_string(i) + " is empty; give a path or leave it out");
  }
}

std::string ParseErrorText(const CLI::ParseError& error, const CLI::App& app) {
  const std::string text = error.what();
  static const std::regex given_twice(R"(^(.+): At Most 1 required but received (\d+)$)");
  std::smatch found;
  if (dynamic_cast<const CLI::ArgumentMismatch*>(&error) != nullptr && std::regex_match(text, found, given_twice)) {
    return found[1].str() + " is given " + found[2].str() + " times; give it once";
  }
  // An argument not expected explains a required one missing too (`vmap build -x`): it is said first.
  if (dynamic_cast<const CLI::ExtrasError*>(&error) != nullptr ||
      dynamic_cast<const CLI::RequiredError*>(&error) != nullptr) {
    std::vector<std::string> extras = app.remaining();
    for (const CLI::App* command : app.get_subcommands()) {
      for (const std::string& extra : command->remaining()) extras.push_back(extra);
    }
    if (!extras.empty()) {
      std::string listed;
      for (const std::string& extra : extras) listed += (listed.empty() ? "" : " ") + extra;
      return (extras.size() > 1 ? "these arguments were not expected: " : "this argument was not expected: ") + listed;
    }
  }
  return text;
}

void RefuseUnknownCommand(int argc, const char* const* argv, const std::vector<std::string>& commands) {
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    if (argument == "--") return;
    if (argument.empty() || argument[0] == '-') continue;
    if (std::find(commands.begin(), commands.end(), argument) != commands.end()) return;
    std::string list;
    for (const std::string& command : commands) list += (list.empty() ? "" : ", ") + command;
    throw InputError("'" + argument + "' is not a vmap command; the commands are " + list + " (see `vmap --help`)");
  }
}

std::string ThreadErrorMessage(const std::exception& error) {
  const auto* system = dynamic_cast<const std::system_error*>(&error);
  if (system == nullptr || system->code() != std::errc::resource_unavailable_try_again) return error.what();
  return "cannot start a thread (" + system->code().message() +
         "): this user's limit of processes and threads is reached (ulimit -u); use fewer --threads, or raise the "
         "limit";
}

}  // namespace vmap::cli
