#pragma once
// An OptionError in a front end's words. The library names a bad option by its field's path ("verifier.seed",
// "extraction_threads"); each front end names fields its own way (the CLI by flag, --threads; Python by keyword,
// threads=), and says the same error with those names.

#include <functional>
#include <string>

#include "vmap/core/error.h"

namespace vmap {

// `error`'s message with its field, and the other fields its problem names, called as `name_of` calls them
// (`name_of(path)` returns "" for a field the front end has no name for: its path is kept). Another field is
// named where its last component first stands alone in the problem, outside the quoted values ('...').
std::string OptionErrorMessage(const OptionError& error, const std::function<std::string(const std::string&)>& name_of);

}  // namespace vmap
