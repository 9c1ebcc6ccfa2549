#include "vmap/localization/localization_map.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "vmap/core/error.h"
#include "vmap/features/camera_mask.h"
#include "vmap/features/matcher_options_json.h"
#include "vmap/features/matcher_registry.h"
#include "vmap/map/map_io.h"
#include "vmap/mapping/recorded_options.h"

namespace vmap {

namespace {

// The map's camera_mask.png against the digest its matcher's record keeps ("1226x370 91.8% 40a71bd7e5820fc9"): a
// mask swapped since (another of the same size) would extract the frames elsewhere than the key images were. Only
// where the record is of the same size: a mask given at another size was resized to the frames' before it was kept.
void CheckRecordedMask(const CameraMask& mask, const std::string& matcher_json,
                       const std::filesystem::path& directory) {
  const nlohmann::json record = nlohmann::json::parse(matcher_json, nullptr, false);
  if (!record.is_object() || !record.contains("camera_mask") || !record["camera_mask"].is_string()) return;
  const std::string recorded = record["camera_mask"].get<std::string>(), kept = mask.Describe();
  const auto size_of = [](const std::string& digest) { return digest.substr(0, digest.find(' ')); };
  if (size_of(recorded) != size_of(kept) || recorded == kept) return;
  throw InputError(fmt::format(
      "map '{}': {} is not the mask the map was built with (its record says {}, the file is {}); put the map's mask "
      "back, or rebuild the map with `vmap build`",
      directory.string(), kCameraMaskFileName, recorded, kept));
}

}  // namespace

LocalizationMap OpenLocalizationMap(const std::filesystem::path& directory, const KeyImageStoreOptions& options,
                                    const MatcherRunSettings& matcher_run) {
  RecordedMap read = ReadRecordedMap(directory);
  std::unique_ptr<Matcher> matcher = CreateMapMatcher(read, directory, matcher_run);
  return OpenLocalizationMap(std::move(read), directory, options, std::move(matcher));
}

std::unique_ptr<Matcher> CreateMapMatcher(const RecordedMap& read, const std::filesystem::path& directory,
                                          const MatcherRunSettings& run) {
  const MatcherOptions options =
      MatcherOptionsFromJson(read.options.matcher_json, (directory / kMapFileName).string(), run);
  std::unique_ptr<Matcher> matcher;
  try {
    matcher = CreateMatcher(options);
  } catch (const InputError& error) {
    // The loader names the file it refuses; its fix may name another model, but the map's is fixed, so the file is
    // what must change. Other errors (a device without CUDA) are the matcher's own.
    if (run.weights.empty() || std::string(error.what()).find(run.weights) == std::string::npos) throw;
    throw OptionError("weights", fmt::format("'{}' are not weights of the map's {} ({}); give weights of that model, "
                                             "or leave them out to read the map's",
                                             run.weights, options.type, error.what()));
  }
  // The frames are extracted within the mask the key images were.
  if (read.map.camera_mask.empty()) return matcher;
  const CameraMask mask(read.map.camera_mask, "the map's " + std::string(kCameraMaskFileName));
  CheckRecordedMask(mask, read.options.matcher_json, directory);
  return WithCameraMask(std::move(matcher), mask);
}

LocalizationMap OpenLocalizationMap(RecordedMap read, const std::filesystem::path& directory,
                                    const KeyImageStoreOptions& options, std::unique_ptr<Matcher> matcher) {
  LocalizationMap opened;
  opened.directory = directory;
  opened.map = std::move(read.map);
  opened.options = std::move(read.options);
  opened.matcher = std::move(matcher);
  opened.experiences = opened.map.experiences;
  opened.keys = LoadKeyImageStore(directory, opened.map, *opened.matcher, options, opened.experiences);
  return opened;
}

LocalizerOptions MapLocalizerOptions(const LocalizationMap& opened) {
  const MapBuilderOptions& recorded = opened.options.builder;
  LocalizerOptions options;
  options.verifier = MapVerifierOptions(recorded.verifier);
  options.similarity = recorded.key_images.similarity;
  options.camera = opened.map.input.camera;
  options.translation = recorded.link_analysis.translation;
  options.map_tau = recorded.key_images.tau;
  return options;
}

std::string QueryResize(const VisualMap& map, const std::string& resize) {
  if (!resize.empty() || map.input.frame_size.empty()) return resize;
  return fmt::format("{}x{}", map.input.frame_size.width, map.input.frame_size.height);
}

LocalizerOptions FollowMap(const LocalizationMap& opened, LocalizerOptions options, const std::string& query_resize) {
  const VisualMap& map = opened.map;
  const LocalizerOptions from_map = MapLocalizerOptions(opened);
  options.verifier = from_map.verifier;
  if (options.verifier_seed >= 0) options.verifier.seed = options.verifier_seed;
  options.similarity = from_map.similarity;
  options.translation = from_map.translation;
  options.map_tau = from_map.map_tau;
  if (options.link_share_tau == 0.0) options.link_share_tau = DefaultTau(opened.matcher->name());
  const std::string map_size = QueryResize(map, "");
  if (from_map.camera && !map_size.empty() && query_resize == map_size) {
    options.camera = from_map.camera;
  } else if (from_map.camera) {
    spdlog::warn("--resize {} differs from the map's frame size {}: headings in pixels only, no relative poses",
                 query_resize, map_size);
  }
  return options;
}

}  // namespace vmap
