#pragma once
// Route planning on a map (stage 3): the key images to follow from one key image to another.
//
// A link joins two consecutive key images of the teach run. It is followed forwards (in the teach run's
// direction) always: the teach run drove it. A link without F (matching failed between its key images) is
// still followed forwards, with a warning: there is no verified guidance between its two key images, and the
// robot has to relocalize after it.
// A link is followed backwards (the robot retracing the teach run in reverse, e.g. reversing with the camera
// facing as in the teach run) only when the map shows that its two key images see the same scene: the link
// has F and at least `min_backward_verified` verified matches. Verification is symmetric (the same matches
// and F, transposed), so such a link guides the robot either way; a link without F, or with fewer verified
// matches, blocks a backward route. (A link below tau, whose S fell under the threshold within one frame,
// has an F as good as any and is followed both ways when it has the matches.)

#include <string>
#include <vector>

#include "vmap/core/option_fields.h"
#include "vmap/map/visual_map.h"

namespace vmap {

struct RouteOptions {
  int min_backward_verified = 20;  // verified matches a link needs to be followed backwards

  // The flag of `vmap route` (--min-backward-verified).
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

struct RouteStep {
  int from_key = 0;
  int to_key = 0;
  int link = 0;             // index into VisualMap::links
  bool backwards = false;   // against the teach run's direction
  bool unverified = false;  // the link has no F (forwards only)
};

struct Route {
  std::vector<int> keys;         // key images in the order to follow, `from` first and `to` last
  std::vector<RouteStep> steps;  // keys.size() - 1 steps
  std::vector<std::string> warnings;
};

// The route with the fewest steps from key image `from` to `to`. Throws InputError naming the key image or
// the link that makes it impossible (a key image that does not exist, a link that cannot be followed
// backwards, key images no link joins).
Route PlanRoute(const VisualMap& map, int from, int to, const RouteOptions& options = {});

// Throws OptionError of `field` (the options' "from", "to", "start_key") when `key` is no key image of `map`: before
// PlanRoute, whose refusal cannot say which option named the key image. A negative key (the options' default) passes.
void CheckKeyImageOption(const VisualMap& map, int key, const char* field);

}  // namespace vmap
