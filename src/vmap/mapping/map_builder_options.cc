#include "vmap/mapping/map_builder_options.h"

#include <algorithm>
#include <thread>

#include <nlohmann/json.hpp>

#include "vmap/core/error.h"
#include "vmap/core/json_fields.h"
#include "vmap/core/option_ranges.h"

namespace vmap {

KeySearch ParseKeySearch(const std::string& name) { return ParseEnum(kKeySearchNames, name, "key-image search"); }

std::string KeySearchName(KeySearch search) { return EnumToName(kKeySearchNames, search); }

KeySearch ResolveKeySearch(const MapBuilderOptions& options) {
  return options.key_search == KeySearch::kAuto ? KeySearch::kSequential : options.key_search;
}

void MapBuilderOptions::Check() const {
  CheckFieldRanges(*this);
  CheckField("key_images", key_images);
  CheckField("verifier", verifier);
  CheckField("link_analysis", link_analysis);
  if (prefetch_frames < 1 || prefetch_frames > 1024) throw OptionError("prefetch_frames", "must be 1 to 1024");
  if (exhaustive && key_search == KeySearch::kBisect) {
    throw OptionError("exhaustive", "is the paper's frame-by-frame scan and key_search bisect skips frames; drop one",
                      {"key_search"});
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

void MapBuilderOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Section("Key images");
  const Nesting at_top_level{/*json_inline=*/true, {}};
  visitor.VisitNested("key_images", key_images, at_top_level);
  visitor.Visit(OptionField{"quality_mean", "--quality", "Mean used by the quality Q: "}.ListingNames(),
                EnumField(quality_mean, kQualityMeanNames, ParseQualityMean));
  visitor.VisitNested("link_analysis", link_analysis, at_top_level);
  visitor.VisitNested("verifier", verifier);
  visitor.Visit({"exhaustive", "--exhaustive",
                 "The paper's exact behaviour: verify every comparison with OpenCV's USAC_MAGSAC to its "
                 "confidence criterion (default: stop once S >= tau is settled; same maps within seed noise)"},
                exhaustive);
  visitor.Visit(OptionField{"search", "--search",
                            "Key-image search: sequential (compare every frame: Algorithm 1), bisect (compare frames "
                            "further ahead, then bisect: fewer network passes, the same map only where S falls with "
                            "distance) or auto (sequential; docs/measurements/deep-matchers.md)"}
                    .Named("key_search"),
                EnumField(key_search, kKeySearchNames, ParseKeySearch));
  visitor.Visit(
      OptionField{"search_window", "--search-window", "bisect: frames compared ahead at most (held in memory)"}
          .Within(2, 4096)
          .Unit("frames"),
      search_window);
  visitor.Section(kRunSection);
  visitor.Visit(
      OptionField{"extraction_threads", "--threads", "Feature-extraction threads, 0 to 256 (0 = one per core)"}
          .NotRecorded()
          .Within(0, kMaxExtractionThreads)
          .Meaning("0: one per core"),
      extraction_threads);
}

}  // namespace vmap
