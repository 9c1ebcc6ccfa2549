#pragma once
// The key images of a map as localization needs them: the matcher's features and the thumbnail of each,
// computed once per map and kept in a cache file inside the map directory.
//
// The cache, MAP/localization_cache.bin, is written atomically. It starts with a fingerprint of map.json's
// bytes, the size and time of last change of each key image's file (and of the experiences' views and the camera
// mask), the matcher's recorded options (Matcher::DescribeOptionsJson), the thumbnail width and the vmap and
// OpenCV versions, and ends with a checksum of its bytes; it is used only when all are unchanged: a rebuilt map, a
// key image replaced, another matcher setting, another vmap, a newer cache format or a damaged cache makes it
// stale, and it is then recomputed and replaced. A map directory that cannot be
// written is not an error (the features are then computed at every start). Matchers that cannot serialise their
// features (Matcher::SerializeFeatures returns "") get no cache.

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/core/option_fields.h"
#include "vmap/features/matcher.h"
#include "vmap/map/experiences.h"
#include "vmap/map/visual_map.h"

namespace vmap {

inline constexpr const char* kLocalizationCacheFileName = "localization_cache.bin";

enum class KeyImageCacheState {
  kOff,          // not asked to use a cache
  kHit,          // read from a valid cache
  kWritten,      // computed, and the cache written
  kNotWritten,   // computed; the cache could not be written (read-only map directory)
  kUnsupported,  // computed; the matcher cannot serialise its features
};
std::string KeyImageCacheStateName(KeyImageCacheState state);

struct KeyImageStoreOptions {
  bool use_cache = true;
  int thumbnail_width = 48;    // ThumbnailDescriptor width (the ranking's)
  int extraction_threads = 0;  // threads extracting key-image features on a cache miss; 0 = one per core

  // No flags: a localization session sets them (its cache option, the ranking's thumbnail width).
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

// A view an experience added to a key image (map/experiences.h), with the matcher's features.
struct KeyImageView {
  int experience = 1;       // Experience::id
  double heading_px = 0.0;  // x in the view minus x in the key image (ExperienceView::heading_px)
  std::shared_ptr<const ImageFeatures> features;
};

struct KeyImageStore {
  std::vector<std::shared_ptr<const ImageFeatures>> features;  // one per key image, in map order
  std::vector<cv::Mat> thumbnails;                             // ThumbnailDescriptor of each key image
  // Per key image, the views of the map's experiences; empty (no list at all) for a map without experiences.
  std::vector<std::vector<KeyImageView>> views;
  KeyImageCacheState cache = KeyImageCacheState::kOff;
  double seconds = 0.0;  // time to load or compute them
  // The map directory the key images were read from (LoadKeyImageStore): a lost frame's key images are extracted
  // again from there with more features (LocalizerOptions::lost_frame_features). Empty: a store built otherwise.
  std::filesystem::path directory;
};

// Reads (or computes and caches) the features of every key image of `map`, read from `map_directory`, and of
// every view of `experiences` (VisualMap::experiences; cached after the key images).
// Throws InputError naming the file when a key image or view cannot be decoded.
KeyImageStore LoadKeyImageStore(const std::filesystem::path& map_directory, const VisualMap& map,
                                const Matcher& matcher, const KeyImageStoreOptions& options,
                                const std::vector<Experience>& experiences = {});

}  // namespace vmap
