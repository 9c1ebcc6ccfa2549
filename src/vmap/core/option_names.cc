#include "vmap/core/option_names.h"

#include <cctype>

namespace vmap {

namespace {

bool IsNameCharacter(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-'; }

// `text` with the first occurrence of `word` that stands alone (not part of a longer name or path, nor inside a
// quoted value) replaced.
std::string ReplaceWord(std::string text, const std::string& word, const std::string& replacement) {
  bool quoted = false;
  for (size_t at = 0; at + word.size() <= text.size(); ++at) {
    // A quote opens after a space or a bracket and closes before one: the apostrophe of "map's" does neither.
    if (text[at] == '\'') {
      if (!quoted && (at == 0 || !IsNameCharacter(text[at - 1]))) {
        quoted = true;
      } else if (quoted && (at + 1 == text.size() || !IsNameCharacter(text[at + 1]))) {
        quoted = false;
      }
      continue;
    }
    if (quoted || text.compare(at, word.size(), word) != 0) continue;
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

std::string OptionErrorMessage(const OptionError& error,
                               const std::function<std::string(const std::string&)>& name_of) {
  std::string problem = error.problem();
  for (const std::string& other : error.others()) {
    const std::string name = name_of(other);
    if (!name.empty()) problem = ReplaceWord(problem, LastComponent(other), name);
  }
  const std::string name = name_of(error.path());
  return (name.empty() ? error.path() : name) + " " + problem;
}

}  // namespace vmap
