#include "vmap/localization/route_belief.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "vmap/core/error.h"
#include "vmap/core/option_ranges.h"
#include "vmap/localization/motion_pace.h"

namespace vmap {

void RouteBeliefOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Section("The belief over the route");
  visitor.Visit(
      OptionField{"min_confidence", "--min-confidence",
                  "A frame is uncertain (not to steer by) when the belief over the route holds less than this near "
                  "its key image (0: never)"}
          .Within(0, 1)
          .Meaning("0: never uncertain"),
      min_confidence);
  visitor.Visit(
      OptionField{"window", "--belief-window",
                  "When the belief doubts the key image, compare key images this many places around the belief's "
                  "peak and move there when it is singled out (0: the belief never moves the estimate)"}
          .Within(0, 50)
          .Meaning("0: the belief never moves the estimate"),
      window);
  visitor.Visit(
      {"move_needs_two_frames", "!--belief-moves-on-one-frame",
       "Move the estimate to the belief's peak when the belief singles it out on one frame (not two running)"},
      move_needs_two_frames);
  // The motion model's probabilities.
  visitor.Visit(OptionField{"stay"}.Within(0, 1), stay);
  visitor.Visit(OptionField{"forward"}.Within(0, 1), forward);
  visitor.Visit(OptionField{"forward2"}.Within(0, 1), forward2);
  visitor.Visit(OptionField{"back"}.Within(0, 1), back);
  visitor.Visit(OptionField{"jump"}.Within(0, 1).ExcludingMin().Meaning(
                    "above 0: a belief that cannot jump can be stuck for ever"),
                jump);
  visitor.Visit(
      OptionField{"motion_steps_per_frame", "--motion-steps-per-frame",
                  "The motion model's steps a frame (0: from the map and the run: the time between frames against "
                  "the time between key images where both have timestamps, else input frames)"}
          .Within(0, kMaxMotionSteps)
          .Meaning("0: from the map and the run"),
      motion_steps_per_frame);
}

void RouteBeliefOptions::Check() const { CheckFieldRanges(*this); }

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

void RouteBelief::Predict(int steps) {
  for (int step = 0; step < steps; ++step) PredictOneStep();
}

void RouteBelief::PredictOneStep() {
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
