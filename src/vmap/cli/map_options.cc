#include "vmap/cli/map_options.h"

#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "vmap/core/error.h"
#include "vmap/features/matcher_registry.h"
#include "vmap/map/map_io.h"
#include "vmap/mapping/recorded_options.h"
#include "vmap/report/html_report.h"
#include "vmap/report/summary.h"

namespace vmap::cli {

namespace {

// "orb 0.5, aliked 0.7, ...": each registered matcher's default tau.
std::string DefaultTaus() {
  std::string text;
  for (const auto& model : MatcherModels()) {
    text += (text.empty() ? "" : ", ") + model.name + " " + fmt::format("{}", model.default_tau);
  }
  return text;
}

}  // namespace

MapBuilderOptions KeyImageFlags::Resolve(const std::string& matcher_type) const {
  MapBuilderOptions resolved = options;
  resolved.key_images.tau = tau ? *tau : DefaultTau(matcher_type);
  CheckField("key_images", resolved.key_images);
  CheckField("link_analysis", resolved.link_analysis);
  return resolved;
}

void AddKeyImageOptions(CLI::App* command, KeyImageFlags& flags, OptionFlags& option_flags, bool with_tau) {
  if (with_tau) {
    option_flags.Record("key_images.tau",
                        command->add_option_function<double>(
                            "-t,--tau", [&flags](double tau) { flags.tau = tau; },
                            "Similarity threshold tau in (0, 1]: lower keeps fewer key images (default: the "
                            "matcher's, " + DefaultTaus() + ")"));
  }
  MapBuilderOptions& o = flags.options;
  option_flags.AddEnumOption(command, "--similarity", o.key_images.similarity, ParseSimilarityMode,
                             SimilarityModeName, "key_images.similarity",
                             "S = verified / tentative matches (inlier-ratio) or / features detected (feature-ratio)");
  option_flags.AddEnumOption(command, "--quality", o.quality_mean, ParseQualityMean, QualityMeanName, "quality_mean",
                             "Mean used by the quality Q: " + ListEnumNames(kQualityMeanNames));
  option_flags.AddFlag(command, "!--no-final-key", o.key_images.final_key, "key_images.final_key",
                       "Do not make the last frame a key image");
  option_flags
      .AddOption(command, "--threads", o.extraction_threads, "extraction_threads",
                 "Feature-extraction threads, 0 to 256 (0 = one per core)")
      ->capture_default_str();
  option_flags
      .AddOption(command, "--min-key-displacement", o.key_images.min_key_displacement,
                 "key_images.min_key_displacement",
                 "Pixels: a frame whose matches with the key image moved less (median) repeats its view and is "
                 "never made a key image; 0 = off (Algorithm 1 as published)")
      ->capture_default_str();
  PoseOptions& pose = o.link_analysis.pose;
  option_flags.AddEnumOption(command, "--pose", pose.method, ParsePoseMethod, PoseMethodName,
                             "link_analysis.pose.method",
                             "Relative pose of each link, with a camera: essential (E on normalised points) or "
                             "fundamental (E = K^T F K)");
  option_flags
      .AddOption(command, "--pose-threshold", pose.threshold, "link_analysis.pose.threshold",
                 "Inlier threshold of the essential matrix, pixels")
      ->capture_default_str();
  option_flags
      .Record("link_analysis.pose.use_all_matches",
              command->add_option_function<std::string>(
                  "--pose-matches",
                  [&pose](const std::string& matches) {
                    const std::optional<bool> all = FindEnum(kPoseMatchesNames, matches);
                    if (!all) {
                      throw InputError("--pose-matches '" + matches +
                                       "': use all (every tentative match) or verified (F's inliers)");
                    }
                    pose.use_all_matches = *all;
                  },
                  "Matches the essential matrix is estimated on: all (tentative) or verified (F's inliers)"))
      ->default_str(EnumToName(kPoseMatchesNames, pose.use_all_matches));
  option_flags
      .AddOption(command, "--max-translation-sigma", o.link_analysis.translation.max_sigma_deg,
                 "link_analysis.translation.max_sigma_deg",
                 "Degrees: a link whose translation direction is less certain than this is marked translation "
                 "unknown (a robot gets its rotation only)")
      ->capture_default_str();
  option_flags
      .AddOption(command, "--min-translation-parallax", o.link_analysis.translation.min_parallax_px,
                 "link_analysis.translation.min_parallax_px",
                 "Pixels: a link whose verified matches moved less than this once its rotation is undone (median) "
                 "is marked translation unknown")
      ->capture_default_str();
  option_flags
      .AddOption(command, "--rival-translation-angle", o.link_analysis.translation.rival_angle_deg,
                 "link_analysis.translation.rival_angle_deg",
                 "Degrees: another minimum of a link's pose cost whose translation points further away than this "
                 "is a rival (see --min-rival-cost-gap)")
      ->capture_default_str();
  option_flags
      .AddOption(command, "--min-rival-cost-gap", o.link_analysis.translation.min_rival_cost_gap,
                 "link_analysis.translation.min_rival_cost_gap",
                 "A link whose rival minimum costs less than this more than its pose (robust Sampson cost) is "
                 "marked translation unknown: its direction is ambiguous (0: never)")
      ->capture_default_str();
  option_flags.AddFlag(command, "--exhaustive", o.exhaustive, "exhaustive",
                       "The paper's exact behaviour: verify every comparison with OpenCV's USAC_MAGSAC to its "
                       "confidence criterion (default: stop once S >= tau is settled; same maps within seed noise)");
  option_flags.AddEnumOption(command, "--search", o.key_search, ParseKeySearch, KeySearchName, "key_search",
                             "Key-image search: sequential (compare every frame: Algorithm 1), bisect (compare frames "
                             "further ahead, then bisect: fewer network passes, the same map only where S falls with "
                             "distance) or auto (sequential; docs/measurements/deep-matchers.md)");
  option_flags
      .AddOption(command, "--search-window", o.search_window, "search_window",
                 "bisect: frames compared ahead at most (held in memory)")
      ->capture_default_str();
}

std::string DescribeOptions(const Matcher& matcher, const MapBuilderOptions& options,
                            const FrameSourceOptions& source) {
  RecordedOptions record;
  record.matcher_json = matcher.DescribeOptionsJson();
  record.builder = options;
  record.source = source;
  return ToJson(record).dump();
}

void WriteReportIfAsked(bool asked, const std::filesystem::path& map_directory) {
  if (asked) WriteMapReport(map_directory);
}

OutputPolicy MapOutputPolicy(const std::string& input) {
  OutputPolicy policy;
  policy.why_not_ours = WhyNotAVmapMap;
  policy.kind = "a vmap map";
  policy.inputs = {input};
  return policy;
}

OutputPolicy SweepOutputPolicy(const std::string& input) {
  OutputPolicy policy;
  policy.why_not_ours = WhyNotAVmapSweep;
  policy.kind = "a vmap sweep";
  policy.inputs = {input};
  return policy;
}

void WriteSweepFiles(const SweepResult& sweep, const std::filesystem::path& directory) {
  WriteFileAtomically(directory / "sweep.md", SweepToMarkdown(sweep));
  WriteFileAtomically(directory / "sweep.csv", SweepToCsv(sweep));
  WriteFileAtomically(directory / kSweepJsonFileName, SweepToJson(sweep));
}

}  // namespace vmap::cli
