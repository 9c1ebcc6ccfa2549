#include "vmap/localization/route.h"

#include <algorithm>
#include <deque>

#include <fmt/format.h>

#include "vmap/core/error.h"
#include "vmap/core/option_ranges.h"

namespace vmap {

void RouteOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit(OptionField{"min_backward_verified", "--min-backward-verified",
                            "Verified matches a link needs to be followed backwards"}
                    .Within(8, 100000)
                    .Meaning("8: the fewest matches F can be verified with"),
                min_backward_verified);
}

void RouteOptions::Check() const { CheckFieldRanges(*this); }

void CheckKeyImageOption(const VisualMap& map, int key, const char* field) {
  const int last = static_cast<int>(map.key_images.size()) - 1;
  if (key > last)
    throw OptionError(field, fmt::format("{} is no key image: the map has key images 0 to {}", key, last));
}

Route PlanRoute(const VisualMap& map, int from, int to, const RouteOptions& options) {
  options.Check();
  const int num_keys = static_cast<int>(map.key_images.size());
  for (int k : {from, to}) {
    if (k < 0 || k >= num_keys) {
      throw InputError(fmt::format("key image {} does not exist; the map has key images 0 to {}", k, num_keys - 1));
    }
  }
  // The steps each key image can take, and why a backward step was refused (for the error message).
  std::vector<std::vector<RouteStep>> steps(num_keys);
  struct Refusal {
    int low_key, high_key;
    std::string text;
  };
  std::vector<Refusal> refusals;
  for (size_t i = 0; i < map.links.size(); ++i) {
    const Link& l = map.links[i];
    steps[l.from_key].push_back({l.from_key, l.to_key, static_cast<int>(i), false, !l.has_fundamental});
    const bool verified = l.has_fundamental && l.num_verified >= options.min_backward_verified;
    if (verified) {
      steps[l.to_key].push_back({l.to_key, l.from_key, static_cast<int>(i), true, false});
    } else {
      refusals.push_back(
          {std::min(l.from_key, l.to_key), std::max(l.from_key, l.to_key),
           fmt::format("link {} (key {} -> {}) is {}", i, l.from_key, l.to_key,
                       !l.has_fundamental
                           ? std::string("not verified (matching failed)")
                           : fmt::format("verified by {} matches only, fewer than min_backward_verified ({}; "
                                         "--min-backward-verified)",
                                         l.num_verified, options.min_backward_verified))});
    }
  }
  // Breadth-first: fewest steps; ties go to the lower link index, so the result is deterministic.
  std::vector<int> previous_step_link(num_keys, -1);
  std::vector<RouteStep> reached_by(num_keys);
  std::vector<bool> seen(num_keys, false);
  std::deque<int> queue{from};
  seen[from] = true;
  while (!queue.empty() && !seen[to]) {
    const int k = queue.front();
    queue.pop_front();
    for (const RouteStep& s : steps[k]) {
      if (seen[s.to_key]) continue;
      seen[s.to_key] = true;
      reached_by[s.to_key] = s;
      previous_step_link[s.to_key] = s.link;
      queue.push_back(s.to_key);
    }
  }
  if (!seen[to]) {
    // Name the refused link nearest to `from` between the two key images (teach-run order).
    std::string why;
    for (const Refusal& r : refusals) {
      if (r.low_key >= std::min(from, to) && r.high_key <= std::max(from, to)) {
        why = "; going backwards needs every link on the way verified, and " + r.text;
        if (from > to) continue;  // keep the last one: the nearest to `from`
        break;
      }
    }
    throw InputError(fmt::format("no route from key image {} to key image {}{}", from, to, why));
  }
  Route route;
  for (int k = to; k != from; k = reached_by[k].from_key) route.steps.push_back(reached_by[k]);
  std::reverse(route.steps.begin(), route.steps.end());
  route.keys.push_back(from);
  for (const RouteStep& s : route.steps) {
    route.keys.push_back(s.to_key);
    if (s.unverified) {
      route.warnings.push_back(
          fmt::format("link {} (key {} -> {}) has no F: no verified guidance between them; "
                      "the robot relocalizes after it",
                      s.link, s.from_key, s.to_key));
    } else if (const Link& link = map.links[s.link];
               !s.backwards && link.num_verified < options.min_backward_verified) {
      // Followed forwards, as the teach run drove it, but on as little evidence as a backward step is refused on (a
      // cut in the recording, a scene that changed): said, so that a planner knows where the guidance is weak.
      route.warnings.push_back(
          fmt::format("link {} (key {} -> {}) is verified by {} matches only (backwards it needs {}): its guidance "
                      "is weak, and the robot may have to relocalize after it",
                      s.link, s.from_key, s.to_key, link.num_verified, options.min_backward_verified));
    }
  }
  return route;
}

}  // namespace vmap
