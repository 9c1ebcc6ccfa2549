// vmap match IMAGE0 IMAGE1: one pair through a matcher and the verifier (pipelines/match_pipeline.h), to try a
// matcher on one's own images and to compare matches across implementations, and the heading of IMAGE1 against
// IMAGE0 (geometry/heading.h; docs/seasons.md).

#include <cmath>
#include <cstdio>

#include <fmt/format.h>

#include "vmap/cli/commands.h"
#include "vmap/cli/option_binder.h"
#include "vmap/cli/other_matcher_flags.h"
#include "vmap/pipelines/match_pipeline.h"

namespace vmap::cli {

namespace {

struct MatchFlags {
  MatchPipelineOptions options;
  bool list = false;
  OptionFlags option_flags;
};

void RunMatch(const MatchFlags& flags) {
  const MatchPipelineOptions& options = flags.options;
  const MatchPipelineResult result = RunMatchPipeline(options);
  const TentativeMatches& matches = result.pair.matches;
  const FundamentalResult& fundamental = result.pair.fundamental;
  const HeadingEstimate& heading = result.pair.heading;

  std::printf("matcher     %s %s\n", result.matcher.c_str(), result.matcher_options_json.c_str());
  std::printf("images      %s (%dx%d), %s (%dx%d)\n", options.image0.c_str(), result.size0.width, result.size0.height,
              options.image1.c_str(), result.size1.width, result.size1.height);
  std::printf("tentative   %zu\n", matches.size());
  std::printf("verified    %d (%s, S = %.4f)\n", fundamental.num_inliers,
              fundamental.success ? "F found" : "no F: too few matches or no model", result.pair.similarity);
  if (fundamental.success) {
    for (int r = 0; r < 3; ++r) {
      std::printf("%s [% .9e % .9e % .9e]\n", r == 0 ? "F          " : "           ", fundamental.F(r, 0),
                  fundamental.F(r, 1), fundamental.F(r, 2));
    }
  }
  if (heading.valid()) {
    // A camera whose distortion does not invert at the heading's point gives no bearing (NaN): said, not printed.
    const std::string degrees = !result.with_camera          ? ""
                                : std::isfinite(heading.deg) ? fmt::format(", {:.3f} deg", heading.deg)
                                                             : ", deg unknown";
    std::printf("heading     %.1f px%s (%s: %d of %d matches, confidence %.3f)\n", heading.px, degrees.c_str(),
                HeadingMethodName(heading.method).c_str(), heading.votes, heading.num_voters, heading.confidence);
  } else {
    std::printf("heading     none (fewer than %d matches agree)\n", options.pair.heading.min_votes);
  }
  std::printf("time        load %.3f s, extract %.3f s (2 images), match %.3f s, verify %.3f s, heading %.4f s\n",
              result.load_seconds, result.pair.extract_seconds, result.pair.match_seconds, result.pair.verify_seconds,
              result.pair.heading_seconds);
  if (flags.list) {
    // A matcher that scores no match (ORB) gives nan, as numpy reads it: a 0 would read as the worst score.
    std::printf("# x0 y0 x1 y1 score inlier\n");
    for (size_t k = 0; k < matches.size(); ++k) {
      std::printf("%.3f %.3f %.3f %.3f %.6g %d\n", matches.points0[k].x, matches.points0[k].y, matches.points1[k].x,
                  matches.points1[k].y, matches.scores.empty() ? std::nan("") : matches.scores[k],
                  fundamental.success ? int(fundamental.inlier_mask[k]) : 0);
    }
  }
}

}  // namespace

void AddMatchCommand(CLI::App& app) {
  auto flags = std::make_shared<MatchFlags>();
  CLI::App* command = app.add_subcommand(
      "match",
      "Match one image pair: tentative matches (in original image pixels, with confidence), the verified "
      "subset and F, and the heading (x in image1 minus x in image0; degrees with --camera)");
  AddOptionFlags(command, flags->options, flags->option_flags);
  command->add_flag("--list", flags->list, "Print every match: x0 y0 x1 y1 score inlier")->group(kOutputSection);
  command->callback([flags] {
    flags->option_flags.Run([&] {
      flags->options.Check();  // a value out of range is said first
      RefuseOtherMatchersFlags(flags->option_flags, flags->options.pair.matcher.type);
      RunMatch(*flags);
    });
  });
}

}  // namespace vmap::cli
