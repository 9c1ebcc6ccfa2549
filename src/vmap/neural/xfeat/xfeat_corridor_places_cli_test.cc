// `vmap localize` with XFeat on corridor_conditions as a map of places: every third teach frame a key image (`vmap
// build --tau 1 --stride 3`) and the repeat localized every third frame, so the run passes a key image every frame, as
// a robot repeats a path taught once per place (a park path taught every few metres). The fixture:
// xfeat_corridor_run.h.

#include <string>

#include <gtest/gtest.h>

#include "vmap/neural/xfeat/xfeat_corridor_run.h"

namespace vmap::neural {
namespace {

class XfeatCorridorPlacesRun : public XfeatCorridorRun {
 protected:
  std::string BuildFlags() const override { return " --tau 1 --stride 3"; }
};

// The belief keeps pace with the run (docs/localize.md, "The motion model's pace"): repeat frames 72-108 started at
// key image 24 (teach frame 72). Key image 29 (teach frame 87) verifies every frame to the route's end while the key
// image after it sees little; a belief moved one step of the motion model a frame (a key image every three frames)
// stays behind the evidence and the tracker is held at 29 from frame 90 to 108 (right there: 30-36). Moved as many
// steps as the map's spacing says (three), the frames are steered by near where they are.
TEST_F(XfeatCorridorPlacesRun, TheBeliefKeepsPaceWithARunThatPassesAKeyImageEveryFrame) {
  ExpectNoFarFrameButWithout(
      " --motion-steps-per-frame 1", "the tracker held at key image 29 to the route's end",
      [&](const std::string& flags) { return SteeredOnRepeat(72, 110, KeyBefore(72), " --stride 3" + flags); });
}

}  // namespace
}  // namespace vmap::neural
