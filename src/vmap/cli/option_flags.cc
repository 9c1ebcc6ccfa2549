#include "vmap/cli/option_flags.h"

#include <cctype>
#include <stdexcept>

namespace vmap::cli {

namespace {

bool IsNameCharacter(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-'; }

// `text` with the first occurrence of `word` that stands alone (not part of a longer name or path) replaced.
std::string ReplaceWord(std::string text, const std::string& word, const std::string& replacement) {
  for (size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) {
    const size_t end = at + word.size();
    const bool joined_before = at > 0 && (IsNameCharacter(text[at - 1]) || text[at - 1] == '.');
    if (joined_before || (end < text.size() && IsNameCharacter(text[end]))) continue;
    return text.replace(at, word.size(), replacement);
  }
  return text;
}

std::string LastComponent(const std::string& path) {
  const size_t dot = path.rfind('.');
  return dot == std::string::npos ? path : path.substr(dot + 1);
}

}  // namespace

CLI::Option* OptionFlags::Record(const std::string& path, CLI::Option* option) {
  Record(path, option->get_name());
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

std::string OptionFlags::Message(const OptionError& error) const {
  std::string problem = error.problem();
  for (const std::string& other : error.others()) {
    const std::string flag = FlagOf(other);
    if (!flag.empty()) problem = ReplaceWord(problem, LastComponent(other), flag);
  }
  const std::string flag = FlagOf(error.path());
  return (flag.empty() ? error.path() : flag) + " " + problem;
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

}  // namespace vmap::cli
