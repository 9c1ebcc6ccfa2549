// What an options struct's Check() costs now that its ranges follow from its field list (core/option_ranges.h):
// EstimateHeading checks its HeadingOptions on every call, so the check is timed beside one heading estimate on
// 60 matches (a frame's comparison), and LocalizerOptions::Check (once per localizer) beside it.
//
//   option_check_bench [calls]

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/geometry/heading.h"
#include "vmap/localization/localizer_options.h"

using namespace vmap;

namespace {

template <typename Work>
double NanosecondsPerCall(int calls, Work&& work) {
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < calls; ++i) work();
  const std::chrono::duration<double, std::nano> spent = std::chrono::steady_clock::now() - start;
  return spent.count() / calls;
}

}  // namespace

int main(int argc, char** argv) {
  const int calls = argc > 1 ? std::atoi(argv[1]) : 200000;
  if (calls < 1) {
    std::fprintf(stderr, "usage: option_check_bench [calls >= 1]\n");
    return 2;
  }
  const HeadingOptions heading;
  const LocalizerOptions localizer;
  std::mt19937 random(0);
  std::uniform_real_distribution<float> coordinate(0.0f, 160.0f);
  std::vector<cv::Point2f> from, to;
  for (int i = 0; i < 60; ++i) {
    from.emplace_back(coordinate(random), coordinate(random) * 0.75f);
    to.emplace_back(from.back().x + 12.0f + (i % 5), from.back().y + (i % 3));
  }
  volatile double sink = 0.0;
  const double heading_check = NanosecondsPerCall(calls, [&] { heading.Check(); });
  const double localizer_check = NanosecondsPerCall(calls / 10 + 1, [&] { localizer.Check(); });
  const double estimate =
      NanosecondsPerCall(calls / 10 + 1, [&] { sink = sink + EstimateHeading(from, to, heading).px; });
  std::printf("HeadingOptions::Check     %8.0f ns a call\n", heading_check);
  std::printf("LocalizerOptions::Check   %8.0f ns a call\n", localizer_check);
  std::printf("EstimateHeading (60 matches, its check included) %8.0f ns a call: the check is %.1f %% of it\n",
              estimate, 100.0 * heading_check / estimate);
  return 0;
}
