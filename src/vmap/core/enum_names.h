#pragma once
// One table of names per enum, read by parsing (options, map.json), printing and the command line's help, so
// that each name is written once:
//
//   inline constexpr EnumName<KeySearch> kKeySearchNames[] = {
//       {KeySearch::kAuto, "auto"}, {KeySearch::kSequential, "sequential"}, {KeySearch::kBisect, "bisect"}};
//   ParseEnum(kKeySearchNames, "bisect", "key-image search")  -> KeySearch::kBisect
//   EnumToName(kKeySearchNames, KeySearch::kAuto)             -> "auto"
//   ListEnumNames(kKeySearchNames)                            -> "auto, sequential or bisect"

#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>

#include "vmap/core/error.h"

namespace vmap {

template <typename Enum>
struct EnumName {
  Enum value;
  const char* name;
};

// The names in table order: "a, b or c" ("a or b"; "a").
template <typename Enum, std::size_t N>
std::string ListEnumNames(const EnumName<Enum> (&names)[N]) {
  std::string text;
  for (std::size_t i = 0; i < N; ++i) {
    if (i > 0) text += i + 1 == N ? " or " : ", ";
    text += names[i].name;
  }
  return text;
}

// The value named `name`, if any.
template <typename Enum, std::size_t N>
std::optional<Enum> FindEnum(const EnumName<Enum> (&names)[N], const std::string& name) {
  for (const auto& entry : names) {
    if (name == entry.name) return entry.value;
  }
  return std::nullopt;
}

// The value named `name`; InputError "unknown <what> '<name>'; use a, b or c" for any other text.
template <typename Enum, std::size_t N>
Enum ParseEnum(const EnumName<Enum> (&names)[N], const std::string& name, const std::string& what) {
  if (const std::optional<Enum> value = FindEnum(names, name)) return *value;
  throw InputError("unknown " + what + " '" + name + "'; use " + ListEnumNames(names));
}

// The name of `value`; a value missing from its table is a programming error (std::logic_error).
template <typename Enum, std::size_t N>
const char* EnumToName(const EnumName<Enum> (&names)[N], Enum value) {
  for (const auto& entry : names) {
    if (entry.value == value) return entry.name;
  }
  throw std::logic_error("an enum value has no name in its table");
}

}  // namespace vmap
