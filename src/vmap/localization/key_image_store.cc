#include "vmap/localization/key_image_store.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <exception>
#include <fstream>
#include <thread>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <spdlog/spdlog.h>

#include "vmap/core/atomic_output.h"
#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/core/file_name_encoding.h"
#include "vmap/core/fnv1a.h"
#include "vmap/core/option_ranges.h"
#include "vmap/core/parallel_for.h"
#include "vmap/core/stopwatch.h"
#include "vmap/localization/key_image_ranking.h"
#include "vmap/map/map_io.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

// Bump when the layout below changes: older caches are then recomputed.
constexpr char kCacheMagic[16] = {'v', 'm', 'a', 'p', '-', 'l', 'o', 'c', 'a', 'l', 'i', 'z', 'e', '-', 'v', '2'};

std::string ReadWholeFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return {};
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Which file `relative` is now: its size and time of last change, as make and ninja tell a changed input (a key image
// copied over another one keeps map.json as it was). Reading every image to hash it would cost about what extracting
// ORB's features does.
std::string FileIdentity(const fs::path& map_directory, const std::string& relative) {
  std::error_code error;
  const fs::path path = map_directory / relative;
  const auto size = fs::file_size(path, error);
  if (error) return relative + " ?";
  const auto changed = fs::last_write_time(path, error);
  if (error) return relative + " ?";
  return relative + " " + std::to_string(size) + " " + std::to_string(changed.time_since_epoch().count());
}

// `images`: the key images and the experiences' views, whose files the cache's features were extracted from.
uint64_t Fingerprint(const fs::path& map_directory, const std::vector<KeyImage>& images, const Matcher& matcher,
                     const KeyImageStoreOptions& options) {
  uint64_t hash = Fnv1a(std::string_view(kCacheMagic, sizeof(kCacheMagic)));
  hash = Fnv1a(ReadWholeFile(map_directory / kMapFileName), hash);
  for (const KeyImage& image : images) hash = Fnv1a(FileIdentity(map_directory, image.image_file), hash);
  hash = Fnv1a(FileIdentity(map_directory, kCameraMaskFileName), hash);
  hash = Fnv1a(matcher.DescribeOptionsJson(), hash);
  // The weights file a deep matcher read, which its record names: weights replaced in place extract otherwise.
  const nlohmann::json record = nlohmann::json::parse(matcher.DescribeOptionsJson(), nullptr, false);
  if (record.is_object() && record.contains("weights") && record["weights"].is_string()) {
    hash = Fnv1a(FileIdentity(map_directory, DecodeFileName(record["weights"].get<std::string>())), hash);
  }
  // Another vmap or OpenCV may extract differently.
  hash = Fnv1a(std::string(VMAP_VERSION) + " " + CV_VERSION, hash);
  return Fnv1a(std::to_string(options.thumbnail_width), hash);
}

template <typename T>
void Append(std::string& out, const T& value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof(value));
}

// Reads the cache file piece by piece, each piece checked against what is left of the file before it is
// allocated: a damaged, sparse or crafted cache costs no more memory than its real contents.
class Reader {
 public:
  explicit Reader(const ContainedFile& file) : file_(file) {}
  template <typename T>
  bool Read(T& value) {
    if (file_.size() - position_ < sizeof(T) || !file_.Read(position_, &value, sizeof(T))) return false;
    position_ += sizeof(T);
    checksum_ = Fnv1a(std::string_view(reinterpret_cast<const char*>(&value), sizeof(T)), checksum_);
    return true;
  }
  bool View(uint64_t size, std::string_view& view) {
    if (file_.size() - position_ < size || size > kMaxPiece) return false;
    buffer_.resize(size);
    if (!file_.Read(position_, buffer_.data(), size)) return false;
    view = buffer_;
    position_ += size;
    checksum_ = Fnv1a(view, checksum_);
    return true;
  }
  // The file ends here with the checksum of every byte before it: a cache damaged in place is recomputed, not read.
  bool AtChecksummedEnd() {
    const uint64_t expected = checksum_;
    uint64_t stored = 0;
    return Read(stored) && stored == expected && position_ == file_.size();
  }

 private:
  // One key image's features: far above the largest matcher's (some MB).
  static constexpr uint64_t kMaxPiece = 256ull << 20;
  const ContainedFile& file_;
  uint64_t position_ = 0;
  std::string buffer_;
  uint64_t checksum_ = kFnv1aOffsetBasis;  // of the bytes read so far
};

bool ReadCache(const fs::path& map_directory, uint64_t fingerprint, const Matcher& matcher, size_t num_keys,
               KeyImageStore& store) {
  // Inside the map folder only, and never a device or a FIFO: a cache is recomputed rather than followed.
  std::string why_not;
  const std::optional<ContainedFile> file = ContainedFile::Open(map_directory, kLocalizationCacheFileName, &why_not);
  if (!file) {
    if (why_not != "is missing") spdlog::info("key-image cache not read: {} {}", kLocalizationCacheFileName, why_not);
    return false;
  }
  Reader reader(*file);
  std::string_view magic;
  uint64_t stored_fingerprint = 0;
  uint32_t stored_keys = 0;
  if (!reader.View(sizeof(kCacheMagic), magic) || magic != std::string_view(kCacheMagic, sizeof(kCacheMagic))) {
    return false;
  }
  if (!reader.Read(stored_fingerprint) || stored_fingerprint != fingerprint) return false;
  if (!reader.Read(stored_keys) || stored_keys != num_keys) return false;
  std::vector<std::shared_ptr<const ImageFeatures>> features;
  std::vector<cv::Mat> thumbnails;
  for (size_t k = 0; k < num_keys; ++k) {
    uint32_t thumbnail_size = 0;
    uint64_t features_size = 0;
    std::string_view thumbnail_bytes, feature_bytes;
    if (!reader.Read(thumbnail_size) || !reader.View(uint64_t{thumbnail_size} * sizeof(float), thumbnail_bytes)) {
      return false;
    }
    if (!reader.Read(features_size)) return false;
    cv::Mat thumbnail(1, static_cast<int>(thumbnail_size), CV_32F);
    if (thumbnail_size > 0) std::memcpy(thumbnail.data, thumbnail_bytes.data(), thumbnail_bytes.size());
    if (!reader.View(features_size, feature_bytes)) return false;
    std::shared_ptr<const ImageFeatures> f;
    try {
      f = matcher.DeserializeFeatures(feature_bytes);
    } catch (const std::exception&) {
      return false;  // crafted bytes that pass the size checks: recomputed like any other bad cache
    }
    if (!f) return false;
    features.push_back(std::move(f));
    thumbnails.push_back(thumbnail);
  }
  if (!reader.AtChecksummedEnd()) return false;
  store.features = std::move(features);
  store.thumbnails = std::move(thumbnails);
  return true;
}

// The cache's bytes, or "" when the matcher cannot serialise its features.
std::string EncodeCache(uint64_t fingerprint, const Matcher& matcher, const KeyImageStore& store) {
  std::string out(kCacheMagic, sizeof(kCacheMagic));
  Append(out, fingerprint);
  Append(out, static_cast<uint32_t>(store.features.size()));
  for (size_t k = 0; k < store.features.size(); ++k) {
    const std::string bytes = matcher.SerializeFeatures(*store.features[k]);
    if (bytes.empty()) return {};
    const cv::Mat& thumbnail = store.thumbnails[k];
    CV_Assert(thumbnail.type() == CV_32F && thumbnail.isContinuous());
    Append(out, static_cast<uint32_t>(thumbnail.total()));
    out.append(reinterpret_cast<const char*>(thumbnail.data), thumbnail.total() * sizeof(float));
    Append(out, static_cast<uint64_t>(bytes.size()));
    out.append(bytes);
  }
  Append(out, Fnv1a(out));
  return out;
}

// `images`: the key images, then the experiences' views (as KeyImage records naming their files).
void ComputeKeyImages(const fs::path& map_directory, const std::vector<KeyImage>& images, const Matcher& matcher,
                      const KeyImageStoreOptions& options, KeyImageStore& store) {
  const size_t n = images.size();
  store.features.assign(n, nullptr);
  store.thumbnails.assign(n, cv::Mat());
  const int threads = options.extraction_threads > 0 ? options.extraction_threads
                                                     : static_cast<int>(std::thread::hardware_concurrency());
  ParallelFor(n, threads, [&](size_t k) {
    const cv::Mat gray = ReadKeyImage(map_directory, images[k], /*grayscale=*/true);
    const cv::Mat bgr = matcher.reads_color() ? ReadKeyImage(map_directory, images[k]) : cv::Mat();
    store.features[k] = matcher.ExtractFrame(gray, bgr.channels() == 3 ? bgr : cv::Mat());
    store.thumbnails[k] = ThumbnailDescriptor(gray, options.thumbnail_width);
  });
}

}  // namespace

std::string KeyImageCacheStateName(KeyImageCacheState state) {
  switch (state) {
    case KeyImageCacheState::kOff:
      return "off";
    case KeyImageCacheState::kHit:
      return "hit";
    case KeyImageCacheState::kWritten:
      return "written";
    case KeyImageCacheState::kNotWritten:
      return "not written";
    case KeyImageCacheState::kUnsupported:
      return "unsupported";
  }
  return "off";
}

void KeyImageStoreOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit(OptionField{"use_cache"}.NotRecorded(), use_cache);
  visitor.Visit(OptionField{"thumbnail_width"}.NotRecorded().Within(8, 512), thumbnail_width);
  visitor.Visit(OptionField{"extraction_threads"}.NotRecorded().Within(0, 256).Meaning("0: one per core"),
                extraction_threads);
}

void KeyImageStoreOptions::Check() const { CheckFieldRanges(*this); }

KeyImageStore LoadKeyImageStore(const fs::path& map_directory, const VisualMap& map, const Matcher& matcher,
                                const KeyImageStoreOptions& options, const std::vector<Experience>& experiences) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  KeyImageStore store;
  store.directory = map_directory;
  // The views are stored and cached as further key images, after the map's own.
  std::vector<KeyImage> images = map.key_images;
  for (const Experience& e : experiences) {
    for (const ExperienceView& v : e.views) {
      KeyImage image;
      image.image_file = v.image_file;
      images.push_back(std::move(image));
    }
  }
  const fs::path cache_file = map_directory / kLocalizationCacheFileName;
  const uint64_t fingerprint = options.use_cache ? Fingerprint(map_directory, images, matcher, options) : 0;
  if (options.use_cache && ReadCache(map_directory, fingerprint, matcher, images.size(), store)) {
    store.cache = KeyImageCacheState::kHit;
  } else {
    ComputeKeyImages(map_directory, images, matcher, options, store);
    if (options.use_cache) {
      const std::string bytes = EncodeCache(fingerprint, matcher, store);
      if (bytes.empty()) {
        store.cache = KeyImageCacheState::kUnsupported;
      } else {
        try {
          WriteFileAtomically(cache_file, bytes);
          store.cache = KeyImageCacheState::kWritten;
        } catch (const std::exception& e) {
          spdlog::info("key-image cache not written ({}); the features are computed at every start", e.what());
          store.cache = KeyImageCacheState::kNotWritten;
        }
      }
    }
  }
  if (!experiences.empty()) {
    store.views.resize(map.key_images.size());
    size_t next = map.key_images.size();
    for (const Experience& e : experiences) {
      for (const ExperienceView& v : e.views)
        store.views.at(v.key).push_back({e.id, v.heading_px, store.features[next++]});
    }
    store.features.resize(map.key_images.size());
    store.thumbnails.resize(map.key_images.size());
  }
  store.seconds = SecondsSince(start);
  return store;
}

}  // namespace vmap
