#include "vmap/localization/heading_continuity.h"

#include <algorithm>
#include <cmath>

namespace vmap {

std::optional<double> HeadingContinuity::Predicted(int key) const {
  const auto previous = std::find_if(previous_headings_.begin(), previous_headings_.end(),
                                     [&](const std::pair<int, double>& h) { return h.first == key; });
  if (previous == previous_headings_.end()) return std::nullopt;
  return previous->second;
}

bool HeadingContinuity::Holds(const KeyComparison& first, const TentativeMatches& guided, double predicted_dx,
                              cv::Size size) const {
  if (options_.continuity_share <= 0.0 || guided.size() == 0 || !PassesGuards(first)) return false;
  // The window of displacements around the prediction: those of bench/evidence_dump's near_L, where it was measured.
  const double half_width = size.width / 40.0, half_height = size.height / 20.0;
  int moving = 0;
  for (size_t i = 0; i < guided.size(); ++i) {
    const double dx = guided.points0[i].x - guided.points1[i].x, dy = guided.points0[i].y - guided.points1[i].y;
    moving += std::abs(dx - predicted_dx) <= half_width && std::abs(dy) <= half_height;
  }
  return moving >= options_.continuity_share * static_cast<double>(guided.size());
}

bool HeadingContinuity::PassesGuards(const KeyComparison& first) const {
  return !(first.heading.confidence < options_.continuity_heading_confidence) &&
         first.log10_nfa <= options_.continuity_max_log10_nfa;
}

void HeadingContinuity::Remember(const FrameComparisons& comparisons, bool guess) {
  previous_headings_.clear();
  for (const FrameComparisons::Memo& m : comparisons) {
    if (std::isfinite(m.comparison.heading.px))
      previous_headings_.emplace_back(m.comparison.key, m.comparison.heading.px);
  }
  follows_a_guess_ = guess;
}

void HeadingContinuity::Reset() {
  previous_headings_.clear();
  follows_a_guess_ = false;
}

}  // namespace vmap
