#include "vmap/cli/map_options.h"

#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "vmap/cli/option_binder.h"
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
                            "matcher's, " +
                                DefaultTaus() + ")"));
  }
  // The verifier's flags are bound by AddVerifierOptions, onto the command's VerifierFlags.
  AddOptionFlags(command, flags.options, option_flags, "", Nesting{false, {"verifier"}});
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
