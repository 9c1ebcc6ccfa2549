#pragma once
// Flags of a matcher other than the one chosen: `--matcher xfeat --aliked-top-k 5` or `--matcher orb --weights x.pt`
// set options no matcher of the run reads. Refused, naming the flag, rather than taken and ignored.

#include <string>

#include "vmap/cli/option_flags.h"

namespace vmap::cli {

// Throws InputError when a flag given sets only fields of matchers other than `matcher` (the matchers' fields have the
// paths "<model>.<key>": MatcherOptions::VisitFields, nested at the top of the command's options).
void RefuseOtherMatchersFlags(const OptionFlags& flags, const std::string& matcher);

}  // namespace vmap::cli
