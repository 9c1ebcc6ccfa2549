// Integer flags read as decimal numbers, whatever CLI11 would make of them.
#pragma once

#include <CLI/CLI.hpp>

namespace vmap::cli {

// CLI11 reads an integer as C does: "000150" is octal (104), "09" no number at all, "0x10" is 16. A frame number
// copied from a file name (000150.png) then chose another frame without a word. Every integer flag of `app` and its
// commands (those whose type is INT) now takes "000150" as 150, and refuses "0x10" saying that it takes decimals.
void ReadIntegerFlagsAsDecimal(CLI::App& app);

}  // namespace vmap::cli
