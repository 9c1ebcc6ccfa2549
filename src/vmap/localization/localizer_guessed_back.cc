// A frame tracked from a guess far behind the place last steered by is asked where it is
// (LocalizerOptions::ask_where_guessed_back). Why: a robot carried back is relocalized on two frames, and across
// lighting the uncertain frames between may move the tracker to a look-alike behind the right key images. The
// kidnapped run of corridor_conditions (repeat frame 110, then 20): repeat frames 20-21 verify 27-30 matches at key
// image 3 (teach frame 9; right: 4-5), uncertain, and frame 22 was tracked there from the guess, where only the key
// image after it (4, which sees little of it) was compared, and steered by a key image early (docs/measurements/
// localization-conditions.md, "A frame tracked from a guess behind is asked where it is"). The move back the frame
// makes is not yet one the run made (ask_where_moved_back asks the frames after it): it is asked as that rule asks,
// and stays tracked, not doubted, where only a far place verifies more.
#include "vmap/localization/localizer.h"

namespace vmap {

bool Localizer::TrackedFromAGuessBehind(int position) const {
  return options_.ask_where_guessed_back && !binary_descriptors_ && steered_before_ >= 0 &&
         position < steered_before_ - kNear;
}

}  // namespace vmap
