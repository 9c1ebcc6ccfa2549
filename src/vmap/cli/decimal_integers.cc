#include "vmap/cli/decimal_integers.h"

#include <algorithm>
#include <string>

namespace vmap::cli {

namespace {

// "000150" -> "150", "-007" -> "-7"; another number that starts with 0 and more ("0x10", "0b1") is refused: CLI11
// would read it in another base. Anything else is left to the flag's own check, which says what the flag takes.
std::string AsDecimal(std::string& text) {
  const size_t digits = !text.empty() && (text[0] == '+' || text[0] == '-') ? 1 : 0;
  if (text.size() < digits + 2 || text[digits] != '0') return "";
  if (text.find_first_not_of("0123456789", digits) != std::string::npos) {
    if (text[digits + 1] == '.' || text[digits + 1] == 'e' || text[digits + 1] == 'E') return "";  // "0.5": no integer
    return text + " is not a decimal integer";
  }
  const size_t first_digit = std::min(text.find_first_not_of('0', digits), text.size() - 1);
  text.erase(digits, first_digit - digits);
  return "";
}

}  // namespace

void ReadIntegerFlagsAsDecimal(CLI::App& app) {
  for (CLI::Option* option : app.get_options()) {
    if (option->get_type_name().rfind("INT", 0) == 0) option->transform(CLI::Validator(AsDecimal, ""));
  }
  for (CLI::App* command : app.get_subcommands({})) ReadIntegerFlagsAsDecimal(*command);
}

}  // namespace vmap::cli
