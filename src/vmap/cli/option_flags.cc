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

}  // namespace vmap::cli
