#pragma once
// Whether a frame stands still against the frame before: a robot that stops is not a tracker held at a key image
// (LocalizerOptions::still_frame_share; the Localizer's StillSinceFrameBefore).

#include "vmap/features/matcher.h"

namespace vmap {

// A frame stands still against the frame before (LocalizerOptions::still_frame_share): at least `share` of their
// matches by `matcher` (unverified) moved less than half a pixel. No match, or `share` 0: not still.
bool StandsStill(const Matcher& matcher, const ImageFeatures& before, const ImageFeatures& frame, double share);

}  // namespace vmap
