#include "vmap/cli/map_options.h"

#include <nlohmann/json.hpp>

#include "vmap/report/html_report.h"

namespace vmap::cli {

MapBuilderOptions KeyImageFlags::Resolve() const {
  MapBuilderOptions options;
  options.key_images.tau = tau;
  options.key_images.similarity = ParseSimilarityMode(similarity);
  options.key_images.final_key = final_key;
  options.quality_mean = ParseQualityMean(quality);
  options.extraction_threads = threads;
  options.exhaustive = exhaustive;
  options.key_search = ParseKeySearch(search);
  options.search_window = search_window;
  options.key_images.Check();
  return options;
}

void AddKeyImageOptions(CLI::App* command, KeyImageFlags& flags, bool with_tau) {
  if (with_tau) {
    command->add_option("-t,--tau", flags.tau, "Similarity threshold tau in (0, 1]: lower keeps fewer key images")
        ->capture_default_str();
  }
  command->add_option("--similarity", flags.similarity,
                      "S = verified / tentative matches (inlier-ratio) or / features detected (feature-ratio)")
      ->capture_default_str();
  command->add_option("--quality", flags.quality, "Mean used by the quality Q: arithmetic or harmonic")
      ->capture_default_str();
  command->add_flag("!--no-final-key", flags.final_key, "Do not make the last frame a key image");
  command->add_option("--threads", flags.threads, "Feature-extraction threads (0 = one per core)")
      ->capture_default_str();
  command->add_flag("--exhaustive", flags.exhaustive,
                    "The paper's exact behaviour: verify every comparison with OpenCV's USAC_MAGSAC to its "
                    "confidence criterion (default: stop once S >= tau is settled; same maps within seed noise)");
  command->add_option("--search", flags.search,
                      "Key-image search: sequential (compare every frame), bisect (compare frames further ahead, "
                      "then bisect; for deep matchers) or auto (bisect for deep matchers, sequential for ORB "
                      "and with --exhaustive)")
      ->capture_default_str();
  command->add_option("--search-window", flags.search_window, "bisect: frames compared ahead at most (held in memory)")
      ->capture_default_str();
}

std::string DescribeOptions(const Matcher& matcher, const MapBuilderOptions& options,
                            const FrameSourceOptions& source) {
  nlohmann::json doc;
  doc["matcher"] = nlohmann::json::parse(matcher.DescribeOptionsJson());
  doc["verifier"] = {{"method", VerifierMethodName(options.verifier.method)},
                     {"threshold", options.verifier.threshold},
                     {"confidence", options.verifier.confidence},
                     {"max_iterations", options.verifier.max_iterations},
                     {"seed", options.verifier.seed},
                     {"min_matches", options.verifier.min_matches}};
  doc["exhaustive"] = options.exhaustive;
  doc["search"] = KeySearchName(ResolveKeySearch(options, matcher));
  doc["search_window"] = options.search_window;
  doc["tau"] = options.key_images.tau;
  doc["similarity"] = SimilarityModeName(options.key_images.similarity);
  doc["final_key"] = options.key_images.final_key;
  doc["quality_mean"] = QualityMeanName(options.quality_mean);
  doc["source"] = {{"format", SourceFormatName(source.format)}, {"first", source.first}, {"last", source.last},
                   {"stride", source.stride},  {"resize", source.resize},     {"strict", source.strict}};
  return doc.dump();
}

void WriteReportIfAsked(bool asked, const std::filesystem::path& map_directory) {
  if (asked) WriteMapReport(map_directory);
}

void WriteSweepReportIfAsked(const std::string& report_directory, const SweepResult& sweep,
                             const std::string& sweep_directory) {
  if (report_directory.empty()) return;
  SweepResult linked = sweep;
  // The per-tau maps are linked from the report: make their paths valid from the report's directory.
  for (SweepRow& row : linked.rows) {
    if (row.map_directory.empty() || sweep_directory.empty()) continue;
    row.map_directory = std::filesystem::absolute(std::filesystem::path(sweep_directory) / row.map_directory).string();
  }
  WriteSweepReport(linked, report_directory);
}

}  // namespace vmap::cli
