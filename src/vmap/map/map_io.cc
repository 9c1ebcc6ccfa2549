#include "vmap/map/map_io.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "vmap/core/atomic_output.h"
#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/core/file_identity.h"
#include "vmap/core/file_name_encoding.h"
#include "vmap/core/image_header.h"
#include "vmap/map/map_files.h"
#include "vmap/map/map_geometry_json.h"
#include "vmap/map/map_json_fields.h"
#include "vmap/sources/frame_source.h"

namespace vmap {
namespace fs = std::filesystem;
using internal::Fields;
using internal::KeyImageSizeProblem;
using internal::Malformed;
using internal::OpenMapFile;
using internal::SizeField;
using nlohmann::json;

namespace {

// What to do about a map file that is there but cannot be opened, by the reason the system gave.
std::string CannotOpenHint(const std::string& why_not) {
  if (why_not.find("Too many open files") != std::string::npos) {
    return "; this process may open no more files: raise the limit (ulimit -n)";
  }
  return "; check that this user may read it (its permissions and its folder's)";
}

constexpr long kMaxInt = std::numeric_limits<int>::max();
constexpr int kRecordBytes = 4 * sizeof(float);

}  // namespace

ContainedFile internal::OpenMapFile(const fs::path& directory, const std::string& relative, const std::string& what,
                                    const fs::path& map_json, const std::string& field) {
  std::string why_not;
  std::optional<ContainedFile> file = ContainedFile::Open(directory, relative, &why_not);
  if (file) return std::move(*file);
  const fs::path path = directory / relative;
  if (why_not == "is missing") {
    throw InputError("map '" + directory.string() +
                     "' is incomplete: " + (what.empty() ? path.string() : what + " '" + path.string() + "'") +
                     " is missing; rebuild the map with `vmap build`");
  }
  // A field of map.json names the file, or the file is one of the map's own (correspondences.bin).
  const std::string named = field.empty() ? relative : field + " '" + relative + "'";
  const fs::path reported = field.empty() ? path : map_json;
  if (why_not.rfind("resolves outside", 0) == 0) {
    Malformed(reported, named + " resolves outside the map directory (a symbolic link leads out)");
  }
  // The file is there and may be fine: what is in the way is this user's access to it, not the map.
  if (why_not.rfind("cannot be opened", 0) == 0) {
    throw InputError("map '" + directory.string() + "': '" + path.string() + "' " + why_not + CannotOpenHint(why_not));
  }
  Malformed(reported, named + " " + why_not);
}

namespace {

// The camera mask map.json names: the map's own file, an 8-bit grey image of the frames' size (its size read from
// its header before it is decoded), something kept.
cv::Mat ReadCameraMask(const std::string& name, const Fields& fields, const fs::path& directory, const fs::path& file,
                       cv::Size frame_size) {
  if (name != kCameraMaskFileName) {
    fields.Fail("input.camera_mask", std::string("must be \"") + kCameraMaskFileName + "\"");
  }
  if (frame_size.empty()) fields.Fail("input.camera_mask", "needs input.frame_size, which the map does not record");
  const ContainedFile image = OpenMapFile(directory, name, "camera mask", file, "input.camera_mask");
  const std::optional<cv::Size> size = ImageHeaderSize(image);
  std::string bytes;
  // A PNG of a frame's size takes far less than 64 MiB; more is not a mask vmap wrote.
  if (!size || *size != frame_size || image.size() > (64ull << 20) || !image.ReadAll(&bytes)) {
    Malformed(file, "input.camera_mask '" + name + "' is not a PNG of the frames' size " +
                        std::to_string(frame_size.width) + "x" + std::to_string(frame_size.height) +
                        "; rebuild the map with `vmap build --camera-mask`");
  }
  cv::Mat mask;
  try {
    mask = cv::imdecode(cv::Mat(1, static_cast<int>(bytes.size()), CV_8U, bytes.data()), cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception&) {
  }
  if (mask.empty() || mask.type() != CV_8UC1 || mask.size() != frame_size) {
    Malformed(file, "input.camera_mask '" + name + "' is not an 8-bit grey image that decodes");
  }
  mask = mask != 0;
  if (cv::countNonZero(mask) == 0) {
    Malformed(file, "input.camera_mask '" + name + "' is black everywhere: no feature could be found");
  }
  return mask;
}

void ReadKeyImages(const json& doc, const Fields& fields, const fs::path& directory, const fs::path& file,
                   VisualMap* map) {
  const json& keys = fields.Array(fields.Required(doc, "", "key_images"), "key_images");
  if (static_cast<long>(keys.size()) > map->num_frames) {
    fields.Fail("key_images", "lists more key images than there are frames (num_frames)");
  }
  std::map<std::string, size_t> key_of_file;  // each key image has a file of its own, as vmap writes them
  for (size_t i = 0; i < keys.size(); ++i) {
    const std::string where = "key_images[" + std::to_string(i) + "]";
    const json& entry = fields.Object(keys[i], where);
    KeyImage k;
    k.frame_index = static_cast<int>(
        fields.Integer(fields.Required(entry, where, "frame_index"), where + ".frame_index", 0, map->num_frames - 1));
    if (i > 0 && k.frame_index <= map->key_images.back().frame_index) {
      fields.Fail(where + ".frame_index", "must be larger than the previous key image's");
    }
    k.source_index = static_cast<int>(fields.Integer(entry, where, "source_index", 0, kMaxInt, k.frame_index));
    const json* timestamp = Fields::Find(entry, "timestamp");
    k.timestamp = timestamp && !timestamp->is_null()
                      ? fields.Number(*timestamp, where + ".timestamp", 0.0, kMaxTimestampSeconds)
                      : -1.0;
    k.source_name = DecodeFileName(fields.String(entry, where, "source_name"));
    k.image_file = DecodeFileName(fields.String(fields.Required(entry, where, "image"), where + ".image"));
    k.num_features = static_cast<int>(fields.Integer(entry, where, "num_features", 0, kMaxInt, 0));
    k.reason = fields.String(entry, where, "reason");
    if (k.image_file.find('\0') != std::string::npos || k.source_name.find('\0') != std::string::npos) {
      fields.Fail(where, "has a name holding a NUL character, which no file name can");
    }
    if (!IsPlainRelativePath(k.image_file)) {
      Malformed(file, where + " image '" + k.image_file + "' points outside the map directory");
    }
    // `vmap report` replaces report/ whole: a key image kept there would go with it.
    if (*fs::path(k.image_file).lexically_normal().begin() == "report") {
      Malformed(file, where + " image '" + k.image_file + "' lies in report/, which `vmap report` replaces");
    }
    const auto [named, first] = key_of_file.emplace(fs::path(k.image_file).lexically_normal().string(), i);
    if (!first) {
      fields.Fail(where + ".image", "names the file of key_images[" + std::to_string(named->second) + "]");
    }
    // Only the header is read here: the image must be a PNG (as vmap writes) or a JPEG (the input's own file,
    // copied) of the map's frame size, so that whoever decodes it later does not meet a decompression bomb.
    const ContainedFile image = OpenMapFile(directory, k.image_file, "key image", file, where + ".image");
    // The file is at fault, not map.json, which names it rightly.
    const auto damaged = [&](const std::string& problem) {
      throw InputError("map '" + directory.string() + "' has a damaged key image: '" + k.image_file + "' " + problem +
                       " (" + where + ".image); rebuild the map with `vmap build`");
    };
    const std::string problem = KeyImageSizeProblem(ImageHeaderSize(image), map->input.frame_size);
    if (!problem.empty()) damaged(problem);
    if (const char* cut = CutShortImage(image)) damaged(std::string("is ") + cut);
    map->key_images.push_back(std::move(k));
  }
  if (map->key_images.empty() && map->num_frames > 0) Malformed(file, "no key images");
  if (const json* count = Fields::Find(doc, "num_key_images")) {
    if (fields.Integer(*count, "num_key_images", 0, kMaxInt) != static_cast<long>(map->key_images.size())) {
      fields.Fail("num_key_images",
                  "does not match the " + std::to_string(map->key_images.size()) + " entries of 'key_images'");
    }
  }
}

// The links and, from correspondences.bin, exactly the records they reference.
void ReadLinks(const json& doc, const Fields& fields, const fs::path& directory, const fs::path& file, VisualMap* map) {
  const json& links = fields.Array(fields.Required(doc, "", "links"), "links");
  const long num_keys = static_cast<long>(map->key_images.size());
  if (static_cast<long>(links.size()) > std::max(num_keys - 1, 0L)) {
    fields.Fail("links", "has more entries than there are pairs of consecutive key images");
  }
  std::vector<std::pair<long, long>> ranges;  // first record and count, per link
  long records_referenced = 0;
  for (size_t i = 0; i < links.size(); ++i) {
    const std::string where = "links[" + std::to_string(i) + "]";
    const json& entry = fields.Object(links[i], where);
    Link l;
    l.from_key =
        static_cast<int>(fields.Integer(fields.Required(entry, where, "from"), where + ".from", 0, num_keys - 1));
    l.to_key = static_cast<int>(fields.Integer(fields.Required(entry, where, "to"), where + ".to", 0, num_keys - 1));
    if (l.to_key <= l.from_key) fields.Fail(where + ".to", "must name a key image after 'from'");
    // A map's links chain its key images in order; a gap would leave two stretches that no route joins.
    if (l.from_key != static_cast<long>(i) || l.to_key != static_cast<long>(i) + 1) {
      fields.Fail(where, fmt::format("joins key images {} and {}; it must join key images {} and {}, as a map's links "
                                     "chain its key images in order",
                                     l.from_key, l.to_key, i, i + 1));
    }
    for (const auto& [name, key] : {std::pair<const char*, int>{"from_frame", l.from_key}, {"to_frame", l.to_key}}) {
      const json* frame = Fields::Find(entry, name);
      if (frame && fields.Integer(*frame, Fields::Join(where, name), 0, kMaxInt) != map->key_images[key].frame_index) {
        fields.Fail(Fields::Join(where, name), "is not the frame of key image " + std::to_string(key));
      }
    }
    // Schema version 1 called the flag `broken`.
    if (const json* below_tau = Fields::Find(entry, "below_tau")) {
      l.below_tau = fields.Bool(*below_tau, where + ".below_tau");
    } else if (const json* broken = Fields::Find(entry, "broken")) {
      l.below_tau = fields.Bool(*broken, where + ".broken");
    }
    l.similarity = fields.Number(fields.Required(entry, where, "similarity"), where + ".similarity", 0.0, 1.0);
    l.num_tentative = static_cast<int>(
        fields.Integer(fields.Required(entry, where, "tentative"), where + ".tentative", 0, kMaxMatchesPerLink));
    l.num_verified = static_cast<int>(
        fields.Integer(fields.Required(entry, where, "verified"), where + ".verified", 0, l.num_tentative));
    // S is the verified matches over a count (key_image_selector.cc), whatever the similarity mode.
    if (l.num_verified == 0 && l.similarity > 0) {
      fields.Fail(where + ".similarity", "is more than 0 while 'verified' is 0; the similarity is the verified share");
    }
    if (const json* F = Fields::Find(entry, "F"); F && !F->is_null()) {
      const bool nine_numbers =
          F->is_array() && F->size() == 9 && std::all_of(F->begin(), F->end(), [](const json& v) {
            return Fields::NumberIn(v, -std::numeric_limits<double>::max(), std::numeric_limits<double>::max());
          });
      if (!nine_numbers) fields.Fail(where + ".F", "must be null or a list of 9 finite numbers");
      if (std::all_of(F->begin(), F->end(), [](const json& v) { return v.get<double>() == 0.0; })) {
        fields.Fail(where + ".F", "is all zeros, which no fundamental matrix is; null says there is none");
      }
      l.has_fundamental = true;
      for (int k = 0; k < 9; ++k) l.F(k / 3, k % 3) = (*F)[k].get<double>();
    }
    long offset = 0, count = 0;
    if (const json* correspondences = Fields::Find(entry, "correspondences")) {
      const std::string field = where + ".correspondences";
      fields.Object(*correspondences, field);
      offset = fields.Integer(*correspondences, field, "offset", 0, std::numeric_limits<long>::max() / kRecordBytes, 0);
      count = fields.Integer(*correspondences, field, "count", 0, kMaxMatchesPerLink, 0);
    }
    if (l.num_verified > count) fields.Fail(where + ".verified", "is more than its correspondences' count");
    ReadLinkGeometryJson(entry, l, file.string(), where);
    ranges.emplace_back(offset, count);
    if (count > 0) records_referenced = std::max(records_referenced, offset + count);
    map->links.push_back(std::move(l));
  }
  // The builder links each key image to the next one it was chosen after: a missing link cannot come from it, and
  // would leave localization and routes two stretches that nothing joins.
  if (num_keys > 1 && links.empty()) {
    fields.Fail("links", fmt::format("is empty although the map has {} key images", num_keys));
  }
  if (num_keys > 1 && static_cast<long>(links.size()) < num_keys - 1) {
    fields.Fail("links", fmt::format("ends at key image {} of the map's {}: key image {} has no link to key image {}",
                                     links.size(), num_keys, links.size(), links.size() + 1));
  }
  if (links.empty()) return;
  // Each link's records are its own (vmap writes them one link after the other).
  std::vector<size_t> by_offset;
  for (size_t i = 0; i < ranges.size(); ++i) {
    if (ranges[i].second > 0) by_offset.push_back(i);
  }
  std::sort(by_offset.begin(), by_offset.end(), [&](size_t a, size_t b) { return ranges[a] < ranges[b]; });
  for (size_t j = 1; j < by_offset.size(); ++j) {
    const auto [offset, count] = ranges[by_offset[j - 1]];
    if (offset + count > ranges[by_offset[j]].first) {
      fields.Fail("links[" + std::to_string(by_offset[j]) + "].correspondences",
                  "overlaps the records of links[" + std::to_string(by_offset[j - 1]) + "]");
    }
  }

  const fs::path binary_file = directory / kCorrespondencesFileName;
  const ContainedFile binary = OpenMapFile(directory, kCorrespondencesFileName, "", file, "");
  // The size first, against what the links say: a file that does not belong to this map.json (or a sparse
  // file of gigabytes) is refused before anything is read.
  const std::uint64_t expected_bytes = static_cast<std::uint64_t>(records_referenced) * kRecordBytes;
  if (binary.size() != expected_bytes) {
    throw InputError("malformed map '" + binary_file.string() + "': it holds " + std::to_string(binary.size()) +
                     " bytes, but the links of map.json reference " + std::to_string(records_referenced) +
                     " records of 16 bytes (" + std::to_string(expected_bytes) +
                     " bytes); the two files do not belong together: rebuild the map with `vmap build`");
  }
  std::vector<float> record_values;
  for (size_t i = 0; i < map->links.size(); ++i) {
    const auto [offset, count] = ranges[i];
    record_values.resize(static_cast<size_t>(count) * 4);
    if (count > 0 && !binary.Read(static_cast<std::uint64_t>(offset) * kRecordBytes, record_values.data(),
                                  record_values.size() * sizeof(float))) {
      throw InputError("cannot read '" + binary_file.string() + "' (it changed while being read?)");
    }
    std::vector<Correspondence>& correspondences = map->links[i].correspondences;
    correspondences.resize(count);
    for (long r = 0; r < count; ++r) {
      const float* record = record_values.data() + 4 * r;  // little-endian on x86 and ARM, as written
      if (!std::isfinite(record[0]) || !std::isfinite(record[1]) || !std::isfinite(record[2]) ||
          !std::isfinite(record[3])) {
        Malformed(binary_file, "record " + std::to_string(offset + r) + " (links[" + std::to_string(i) +
                                   "]) holds a coordinate that is not a finite number");
      }
      correspondences[r] = {{record[0], record[1]}, {record[2], record[3]}};
    }
  }
}

void ReadEvaluations(const json& doc, const Fields& fields, VisualMap* map) {
  const json* evaluations = Fields::Find(doc, "evaluations");
  if (!evaluations) return;
  fields.Object(*evaluations, "evaluations");
  const char* names[] = {"key_frame", "frame", "similarity", "tentative", "verified", "matched"};
  const json* columns[6];
  for (int c = 0; c < 6; ++c) {
    columns[c] =
        &fields.Array(fields.Required(*evaluations, "evaluations", names[c]), Fields::Join("evaluations", names[c]));
    if (columns[c]->size() != columns[0]->size()) fields.Fail("evaluations", "has columns of different lengths");
  }
  const long last_frame = map->num_frames - 1;
  // Checked with the cheap predicates first; the message is only built for a value that fails.
  const auto field = [&](int c, size_t i) {
    return "evaluations." + std::string(names[c]) + "[" + std::to_string(i) + "]";
  };
  const size_t n = columns[0]->size();
  map->evaluations.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    const json& key_frame = (*columns[0])[i];
    const json& frame = (*columns[1])[i];
    const json& similarity = (*columns[2])[i];
    const json& tentative = (*columns[3])[i];
    const json& verified = (*columns[4])[i];
    const json& matched = (*columns[5])[i];
    if (!Fields::IntegerIn(key_frame, 0, last_frame)) fields.Integer(key_frame, field(0, i), 0, last_frame);
    if (!Fields::IntegerIn(frame, 0, last_frame)) fields.Integer(frame, field(1, i), 0, last_frame);
    if (!Fields::NumberIn(similarity, 0.0, 1.0)) fields.Number(similarity, field(2, i), 0.0, 1.0);
    if (!Fields::IntegerIn(tentative, 0, kMaxMatchesPerLink)) {
      fields.Integer(tentative, field(3, i), 0, kMaxMatchesPerLink);
    }
    const long tentative_count = tentative.get<long>();
    if (!Fields::IntegerIn(verified, 0, tentative_count)) fields.Integer(verified, field(4, i), 0, tentative_count);
    if (!matched.is_boolean()) fields.Bool(matched, field(5, i));
    map->evaluations.push_back({key_frame.get<int>(), frame.get<int>(), similarity.get<double>(), tentative.get<int>(),
                                verified.get<int>(), matched.get<bool>()});
  }
}

VisualMap ReadCheckedMap(const fs::path& directory) {
  std::error_code ec;
  if (!fs::is_directory(directory, ec)) {
    if (fs::exists(directory, ec)) {
      throw InputError("'" + directory.string() +
                       "' is not a map: a map is the folder `vmap build -o` wrote; "
                       "give that folder");
    }
    throw InputError("map directory '" + directory.string() + "' does not exist; build one with `vmap build`");
  }
  const fs::path file = directory / kMapFileName;
  const ContainedJson parsed = ReadContainedJson(directory, kMapFileName, kMaxMapJsonBytes, kMaxMapJsonValues);
  if (parsed.missing) {
    // A sweep's folder holds its maps one level down (`vmap sweep --maps`): named, rather than only what is missing.
    std::string within;
    for (const fs::directory_entry& entry : fs::directory_iterator(directory, ec)) {
      if (fs::is_regular_file(entry.path() / kMapFileName, ec) && (within.empty() || entry.path().string() < within)) {
        within = entry.path().string();
      }
    }
    throw InputError("'" + directory.string() + "' is not a map: " + file.string() + " is missing" +
                     (within.empty() ? "" : "; the maps are in its folders, e.g. '" + within + "'"));
  }
  if (parsed.why_not.find(" cannot be opened") != std::string::npos) {
    throw InputError("map '" + directory.string() + "': " + parsed.why_not + CannotOpenHint(parsed.why_not));
  }
  if (!parsed.document) Malformed(file, parsed.why_not);
  const json& doc = *parsed.document;
  if (!doc.is_object() || doc.value("format", json()) != "vmap-map") {
    Malformed(file, "not a vmap map.json (it has no \"format\": \"vmap-map\")");
  }
  Fields fields(file);
  const long version =
      fields.Integer(fields.Required(doc, "", "schema_version"), "schema_version", 1, std::numeric_limits<long>::max());
  if (version > kMapSchemaVersion) {
    throw InputError("map '" + file.string() + "' has schema version " + std::to_string(version) +
                     ", newer than this vmap understands (" + std::to_string(kMapSchemaVersion) + "); update vmap");
  }
  VisualMap map;
  const json* input = Fields::Find(doc, "input");
  // Every map since schema 2 records its input: how it was made, and the frame size and camera it is read at.
  if (!input && version >= 2) fields.Fail("input", "is missing");  // Fail gives the fix
  if (input) {
    fields.Object(*input, "input");
    map.input.path = DecodeFileName(fields.String(*input, "input", "path"));
    if (map.input.path.find('\0') != std::string::npos) fields.Fail("input.path", "holds a NUL character");
    map.input.absolute_path = DecodeFileName(fields.String(*input, "input", "absolute_path"));
    if (map.input.absolute_path.find('\0') != std::string::npos) {
      fields.Fail("input.absolute_path", "holds a NUL character");
    }
    const std::string format = fields.String(*input, "input", "format");
    try {
      map.input.format = ParseSourceFormat(format.empty() ? "auto" : format);
    } catch (const InputError&) {
      fields.Fail("input.format", "is not a known format ('" + format + "')");
    }
    map.input.native_size = SizeField(fields, *input, "input", "native_size");
    map.input.frame_size = SizeField(fields, *input, "input", "frame_size");
    map.input.fps = fields.Number(*input, "input", "fps", 0.0, kMaxFramesPerSecond, 0.0);
    if (const json* camera = Fields::Find(*input, "camera"); camera && !camera->is_null()) {
      map.input.camera = CameraFromJson(*camera, file.string(), "input.camera");
    }
  }
  const json* options = Fields::Find(doc, "options");
  map.options_json = options ? fields.Object(*options, "options").dump() : "{}";
  map.num_frames = static_cast<int>(fields.Integer(fields.Required(doc, "", "num_frames"), "num_frames", 0, kMaxInt));
  map.skipped_frames = static_cast<int>(fields.Integer(doc, "", "skipped_frames", 0, kMaxInt, 0));
  // The frames of a map that has any were read at this size, and vmap reads none with a side under
  // kMinFrameSide or more pixels than a frame may have (it skips them): such a size contradicts the frames.
  // 0x0 says the size is not recorded (a snapshot taken before the source knew it): key images then stand
  // for themselves.
  const cv::Size frame_size = map.input.frame_size;
  if (input && Fields::Find(*input, "frame_size") && map.num_frames > 0 && frame_size != cv::Size() &&
      !FrameSizeProblem(frame_size).empty()) {
    fields.Fail("input.frame_size", "is " + std::to_string(frame_size.width) + "x" + std::to_string(frame_size.height) +
                                        " although the map has frames, " + "which are never " +
                                        FrameSizeProblem(frame_size));
  }
  map.quality = fields.Number(fields.Required(doc, "", "quality"), "quality", 0.0, 1.0);
  map.seconds = fields.Number(doc, "", "seconds", 0.0, 1e9, 0.0);
  if (const json* coverage = Fields::Find(doc, "coverage")) {
    fields.Object(*coverage, "coverage");
    Coverage read;
    read.num_frames = static_cast<int>(
        fields.Integer(fields.Required(*coverage, "coverage", "frames"), "coverage.frames", 0, map.num_frames));
    read.first_source_index = static_cast<int>(fields.Integer(
        fields.Required(*coverage, "coverage", "first_source_index"), "coverage.first_source_index", -1, kMaxInt));
    read.last_source_index = static_cast<int>(fields.Integer(
        fields.Required(*coverage, "coverage", "last_source_index"), "coverage.last_source_index", -1, kMaxInt));
    const std::string end = fields.String(fields.Required(*coverage, "coverage", "end"), "coverage.end");
    const std::optional<CoverageEnd> known = FindEnum(kCoverageEndNames, end);
    if (!known) fields.Fail("coverage.end", "must be " + ListEnumNames(kCoverageEndNames));
    read.end = *known;
    map.coverage = read;
  }
  if (const json* mask = input ? Fields::Find(*input, "camera_mask") : nullptr; mask && !mask->is_null()) {
    map.camera_mask = ReadCameraMask(fields.String(*mask, "input.camera_mask"), fields, directory, file, frame_size);
  }
  ReadKeyImages(doc, fields, directory, file, &map);
  ReadLinks(doc, fields, directory, file, &map);
  ReadEvaluations(doc, fields, &map);
  if (const json* experiences = Fields::Find(doc, "experiences")) {
    map.experiences = ExperiencesFromJson(*experiences, map, directory, file);
  }
  return map;
}

}  // namespace

VisualMap ReadMap(const fs::path& directory) {
  // A run writing snapshots of the map (`build --snapshot-every`, the ROS teach node) replaces its folder whole, by a
  // rename, while this reads its files one after the other: a read during which the folder changed is read again, so
  // that a reader gets one snapshot or the next, never a mix of the two (nor a "malformed" for the mix).
  constexpr int kAttempts = 10;
  for (int attempt = 1;; ++attempt) {
    const std::optional<FileIdentity> before = IdentityOf(directory);
    const auto unchanged = [&] {
      const std::optional<FileIdentity> now = IdentityOf(directory);
      return SameFile(now, before) || (!now && !before);  // still the same folder, or still none
    };
    try {
      VisualMap map = RethrowAsInputError(
          [&] {
            return ErrorContext{"cannot read the map '" + directory.string() + "'",
                                "check that it exists and that you may read it"};
          },
          [&] { return ReadCheckedMap(directory); });
      if (unchanged()) return map;
    } catch (const InputError&) {
      if (unchanged()) throw;
    }
    if (attempt == kAttempts) {
      throw InputError(
          fmt::format("the map '{}' was replaced {} times while it was read (a run writing snapshots of "
                      "it?); read it again later",
                      directory.string(), kAttempts));
    }
  }
}

std::string WhyNotAVmapMap(const fs::path& directory) {
  const ContainedJson parsed = ReadContainedJson(directory, kMapFileName, kMaxMapJsonBytes, kMaxMapJsonValues);
  if (parsed.missing) return "it has no map.json";
  if (!parsed.document) return "its " + parsed.why_not;
  const json& doc = *parsed.document;
  if (!doc.is_object() || doc.value("format", json()) != "vmap-map") {
    return "its map.json is not a vmap map's: it has no \"format\": \"vmap-map\"";
  }
  if (!doc.value("schema_version", json()).is_number_integer()) {
    return "its map.json has no integer \"schema_version\"";
  }
  return "";
}

}  // namespace vmap
