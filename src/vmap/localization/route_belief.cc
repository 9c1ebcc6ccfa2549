#include "vmap/localization/route_belief.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <fmt/format.h>

#include "vmap/core/error.h"

namespace vmap {

void RouteBeliefOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit({"min_confidence", "--min-confidence",
                 "A frame is uncertain (not to steer by) when the belief over the route holds less than this near "
                 "its key image (0: never)"},
                min_confidence);
  visitor.Visit({"window", "--belief-window",
                 "When the belief doubts the key image, compare key images this many places around the belief's "
                 "peak and move there when it is singled out (0: the belief never moves the estimate)"},
                window);
  visitor.Visit(
      {"move_needs_two_frames", "!--belief-moves-on-one-frame",
       "Move the estimate to the belief's peak when the belief singles it out on one frame (not two running)"},
      move_needs_two_frames);
  visitor.Visit({"stay"}, stay);
  visitor.Visit({"forward"}, forward);
  visitor.Visit({"forward2"}, forward2);
  visitor.Visit({"back"}, back);
  visitor.Visit({"jump"}, jump);
}

void RouteBeliefOptions::Check() const {
  const RouteBeliefOptions defaults;  // the defaults the messages give, as declared
  const std::pair<const char*, double> steps[] = {
      {"stay", stay}, {"forward", forward}, {"forward2", forward2}, {"back", back}, {"jump", jump}};
  for (const auto& [name, value] : steps) {
    if (!(value >= 0.0 && value <= 1.0)) {
      throw OptionError(name, fmt::format("{} is outside [0, 1] (a probability of the motion model)", value));
    }
  }
  if (!(jump > 0.0)) throw OptionError("jump", "must be above 0: a belief that cannot jump can be stuck for ever");
  if (window < 0 || window > 50) {
    throw OptionError("window",
                      fmt::format("{} is outside [0, 50] (default 2; 0: the belief never moves the estimate)", window));
  }
  if (!(min_confidence >= 0.0 && min_confidence <= 1.0)) {
    throw OptionError("min_confidence",
                      fmt::format("{} is outside [0, 1] (default 0.5; 0: never uncertain)", min_confidence));
  }
}

RouteBelief::RouteBelief(int positions, const RouteBeliefOptions& options) : options_(options) {
  options_.Check();
  p_.assign(std::max(positions, 1), 0.0);
  Reset();
}

void RouteBelief::Reset() { std::fill(p_.begin(), p_.end(), 1.0 / p_.size()); }

void RouteBelief::Start(int position, double mass) {
  Reset();
  if (position < 0 || position >= static_cast<int>(p_.size())) return;
  for (double& v : p_) v *= 1.0 - mass;
  p_[position] += mass;
}

void RouteBelief::Predict() {
  const int n = static_cast<int>(p_.size());
  const double total = options_.stay + options_.forward + options_.forward2 + options_.back + options_.jump;
  const double steps[4][2] = {{0, options_.stay / total},
                              {1, options_.forward / total},
                              {2, options_.forward2 / total},
                              {-1, options_.back / total}};
  scratch_.assign(n, options_.jump / total / n);
  for (int i = 0; i < n; ++i) {
    for (const auto& [step, probability] : steps) {
      // Steps past either end of the route stay at that end.
      const int to = std::clamp(i + static_cast<int>(step), 0, n - 1);
      scratch_[to] += probability * p_[i];
    }
  }
  p_.swap(scratch_);
}

void RouteBelief::Weigh(int position, double log_ratio) {
  const double factor = std::exp(std::clamp(log_ratio, -50.0, 50.0));
  for (const int i : {position - 1, position}) {
    if (i >= 0 && i < static_cast<int>(p_.size())) p_[i] *= factor;
  }
}

void RouteBelief::Normalize() {
  const double sum = std::accumulate(p_.begin(), p_.end(), 0.0);
  if (!(sum > 0.0) || !std::isfinite(sum)) {
    Reset();
    return;
  }
  for (double& v : p_) v /= sum;
}

double RouteBelief::MassWithin(int position, int radius) const {
  double mass = 0.0;
  for (int i = std::max(0, position - radius); i <= position + radius && i < static_cast<int>(p_.size()); ++i) {
    mass += p_[i];
  }
  return mass;
}

int RouteBelief::Peak() const {
  if (p_.empty()) return -1;
  return static_cast<int>(std::max_element(p_.begin(), p_.end()) - p_.begin());
}

}  // namespace vmap
