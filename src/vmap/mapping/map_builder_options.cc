#include "vmap/mapping/map_builder_options.h"

#include <algorithm>
#include <thread>

#include <nlohmann/json.hpp>

#include "vmap/core/error.h"
#include "vmap/core/json_fields.h"

namespace vmap {

KeySearch ParseKeySearch(const std::string& name) { return ParseEnum(kKeySearchNames, name, "key-image search"); }

std::string KeySearchName(KeySearch search) { return EnumToName(kKeySearchNames, search); }

KeySearch ResolveKeySearch(const MapBuilderOptions& options) {
  return options.key_search == KeySearch::kAuto ? KeySearch::kSequential : options.key_search;
}

void MapBuilderOptions::Check() const {
  CheckField("key_images", key_images);
  CheckField("verifier", verifier);
  CheckField("link_analysis", link_analysis);
  if (prefetch_frames < 1 || prefetch_frames > 1024) throw OptionError("prefetch_frames", "must be 1 to 1024");
  if (extraction_threads < 0 || extraction_threads > kMaxExtractionThreads) {
    throw OptionError("extraction_threads",
                      "must be 0 to " + std::to_string(kMaxExtractionThreads) + " (0 = one per core)");
  }
  if (exhaustive && key_search == KeySearch::kBisect) {
    throw OptionError("exhaustive", "is the paper's frame-by-frame scan and key_search bisect skips frames; drop one",
                      {"key_search"});
  }
  if (search_window < 2 || search_window > 4096) {
    throw OptionError("search_window", "must be 2 to 4096 frames (default 32)");
  }
}

int MapBuilderOptions::ExtractionThreads() const {
  if (extraction_threads > 0) return extraction_threads;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

VerifierOptions DecisionVerifier(const MapBuilderOptions& options) {
  VerifierOptions verifier = options.verifier;
  verifier.own_magsac = !options.exhaustive && verifier.method == VerifierMethod::kMagsac;
  return verifier;
}

nlohmann::json ToJson(const MapBuilderOptions& options) {
  nlohmann::json record = ToJson(options.key_images);
  record.update(ToJson(options.link_analysis));
  record["verifier"] = ToJson(options.verifier);
  record["exhaustive"] = options.exhaustive;
  record["search"] = KeySearchName(ResolveKeySearch(options));
  record["search_window"] = options.search_window;
  record["quality_mean"] = QualityMeanName(options.quality_mean);
  return record;
}

void FromJson(const JsonFieldReader& fields, MapBuilderOptions* options) {
  FromJson(fields, &options->key_images);
  FromJson(fields, &options->link_analysis);
  FromJson(fields.Object("verifier"), &options->verifier);
  fields.Read("exhaustive", &options->exhaustive);
  fields.Read("search", &options->key_search, kKeySearchNames);
  fields.Read("search_window", &options->search_window);
  fields.Read("quality_mean", &options->quality_mean, kQualityMeanNames);
}

}  // namespace vmap
