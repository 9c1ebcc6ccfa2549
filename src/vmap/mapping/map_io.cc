#include "vmap/mapping/map_io.h"

#include <cstring>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "vmap/core/atomic_output.h"
#include "vmap/core/error.h"
#include "vmap/mapping/map_geometry_json.h"

namespace vmap {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

json TimestampJson(double t) { return t < 0 ? json(nullptr) : json(t); }

json SizeJson(const cv::Size& s) { return json::array({s.width, s.height}); }

json MapDocument(const VisualMap& map, const std::vector<long>& offsets) {
  json doc;
  doc["format"] = "vmap-map";
  doc["schema_version"] = kMapSchemaVersion;
  doc["vmap_version"] = VMAP_VERSION;
  doc["input"] = {{"path", map.input.path},
                  {"format", SourceFormatName(map.input.format)},
                  {"native_size", SizeJson(map.input.native_size)},
                  {"frame_size", SizeJson(map.input.frame_size)},
                  {"fps", map.input.fps}};
  doc["input"]["camera"] = map.input.camera ? CameraToJson(*map.input.camera) : json(nullptr);
  doc["conventions"] = MapConventionsJson();
  doc["options"] = map.options_json.empty() ? json::object() : json::parse(map.options_json);
  doc["num_frames"] = map.num_frames;
  doc["skipped_frames"] = map.skipped_frames;
  doc["num_key_images"] = map.key_images.size();
  doc["quality"] = map.quality;
  doc["seconds"] = map.seconds;
  json keys = json::array();
  for (const KeyImage& k : map.key_images) {
    keys.push_back({{"frame_index", k.frame_index},
                    {"source_index", k.source_index},
                    {"timestamp", TimestampJson(k.timestamp)},
                    {"source_name", k.source_name},
                    {"image", k.image_file},
                    {"num_features", k.num_features},
                    {"reason", k.reason}});
  }
  doc["key_images"] = std::move(keys);
  json links = json::array();
  for (size_t i = 0; i < map.links.size(); ++i) {
    const Link& l = map.links[i];
    json F = nullptr;
    if (l.has_fundamental) {
      F = json::array();
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) F.push_back(l.F(r, c));
    }
    json link = {{"from", l.from_key},
                 {"to", l.to_key},
                 {"from_frame", map.key_images.at(l.from_key).frame_index},
                 {"to_frame", map.key_images.at(l.to_key).frame_index},
                 {"below_tau", l.below_tau},
                 {"similarity", l.similarity},
                 {"tentative", l.num_tentative},
                 {"verified", l.num_verified},
                 {"F", F},
                 {"correspondences", {{"offset", offsets[i]}, {"count", l.correspondences.size()}}}};
    AddLinkGeometryJson(l, link);
    links.push_back(std::move(link));
  }
  doc["links"] = std::move(links);
  // Column-wise: a long sequence has one evaluation per frame or more.
  json ev = {{"key_frame", json::array()}, {"frame", json::array()},    {"similarity", json::array()},
             {"tentative", json::array()}, {"verified", json::array()}, {"matched", json::array()}};
  for (const Evaluation& e : map.evaluations) {
    ev["key_frame"].push_back(e.key_frame);
    ev["frame"].push_back(e.frame);
    ev["similarity"].push_back(e.similarity);
    ev["tentative"].push_back(e.num_tentative);
    ev["verified"].push_back(e.num_verified);
    ev["matched"].push_back(e.matched);
  }
  doc["evaluations"] = std::move(ev);
  return doc;
}

std::vector<long> CorrespondenceOffsets(const VisualMap& map) {
  std::vector<long> offsets;
  long offset = 0;
  for (const Link& l : map.links) {
    offsets.push_back(offset);
    offset += static_cast<long>(l.correspondences.size());
  }
  return offsets;
}

[[noreturn]] void Malformed(const fs::path& file, const std::string& what) {
  throw InputError("malformed map '" + file.string() + "': " + what +
                   "; rebuild the map with `vmap build`");
}

// Reads a required field with a message that names it.
template <typename T>
T Field(const json& object, const char* name, const fs::path& file, const std::string& where) {
  auto it = object.find(name);
  if (it == object.end()) Malformed(file, where + " has no field '" + name + "'");
  try {
    return it->get<T>();
  } catch (const json::exception&) {
    Malformed(file, where + " field '" + name + "' has the wrong type");
  }
}

cv::Size SizeField(const json& object, const char* name) {
  auto it = object.find(name);
  if (it == object.end() || !it->is_array() || it->size() != 2) return {};
  return {(*it)[0].get<int>(), (*it)[1].get<int>()};
}

// A key-image path must stay inside the map directory: no absolute paths, no "..".
bool IsSafeRelativePath(const std::string& path) {
  if (path.empty()) return false;
  const fs::path p(path);
  if (p.is_absolute() || p.has_root_name() || p.has_root_directory()) return false;
  for (const auto& part : p) {
    if (part == "..") return false;
  }
  return true;
}

}  // namespace

std::string MapToJson(const VisualMap& map) { return MapDocument(map, CorrespondenceOffsets(map)).dump(1); }

void WriteMapFiles(const VisualMap& map, const fs::path& directory) {
  const std::vector<long> offsets = CorrespondenceOffsets(map);
  std::string binary;
  for (const Link& l : map.links) {
    for (const Correspondence& c : l.correspondences) {
      const float record[4] = {c.p0.x, c.p0.y, c.p1.x, c.p1.y};
      binary.append(reinterpret_cast<const char*>(record), sizeof(record));  // x86/ARM: little-endian
    }
  }
  WriteFileAtomically(directory / kCorrespondencesFileName, binary);
  WriteFileAtomically(directory / kMapFileName, MapDocument(map, offsets).dump(1) + "\n");
}

VisualMap ReadMap(const fs::path& directory) {
  if (!fs::is_directory(directory)) {
    throw InputError("map directory '" + directory.string() + "' does not exist; build one with `vmap build`");
  }
  const fs::path file = directory / kMapFileName;
  std::ifstream in(file);
  if (!in) throw InputError("'" + directory.string() + "' is not a map: " + file.string() + " is missing");
  json doc;
  try {
    doc = json::parse(in);
  } catch (const json::parse_error& e) {
    Malformed(file, std::string("not valid JSON (") + e.what() + ")");
  }
  if (!doc.is_object() || doc.value("format", "") != "vmap-map") Malformed(file, "not a vmap map.json");
  const int version = Field<int>(doc, "schema_version", file, "map.json");
  if (version > kMapSchemaVersion) {
    throw InputError("map '" + file.string() + "' has schema version " + std::to_string(version) +
                     ", newer than this vmap understands (" + std::to_string(kMapSchemaVersion) + "); update vmap");
  }
  VisualMap map;
  const json& input = doc.contains("input") ? doc["input"] : json::object();
  map.input.path = input.value("path", "");
  map.input.format = ParseSourceFormat(input.value("format", "auto"));
  map.input.native_size = SizeField(input, "native_size");
  map.input.frame_size = SizeField(input, "frame_size");
  map.input.fps = input.value("fps", 0.0);
  if (input.contains("camera") && !input["camera"].is_null()) {
    map.input.camera = CameraFromJson(input["camera"], file.string(), "input.camera");
  }
  map.options_json = doc.contains("options") ? doc["options"].dump() : "{}";
  map.num_frames = Field<int>(doc, "num_frames", file, "map.json");
  map.skipped_frames = doc.value("skipped_frames", 0);
  map.quality = Field<double>(doc, "quality", file, "map.json");
  map.seconds = doc.value("seconds", 0.0);

  const json& keys = doc.contains("key_images") ? doc["key_images"] : json();
  if (!keys.is_array()) Malformed(file, "'key_images' is missing or not a list");
  for (size_t i = 0; i < keys.size(); ++i) {
    const std::string where = "key_images[" + std::to_string(i) + "]";
    KeyImage k;
    k.frame_index = Field<int>(keys[i], "frame_index", file, where);
    k.source_index = keys[i].value("source_index", k.frame_index);
    k.timestamp = keys[i].contains("timestamp") && keys[i]["timestamp"].is_number() ? keys[i]["timestamp"].get<double>()
                                                                                    : -1.0;
    k.source_name = keys[i].value("source_name", "");
    k.image_file = Field<std::string>(keys[i], "image", file, where);
    k.num_features = keys[i].value("num_features", 0);
    k.reason = keys[i].value("reason", "");
    if (!IsSafeRelativePath(k.image_file)) {
      Malformed(file, where + " image '" + k.image_file + "' points outside the map directory");
    }
    if (!fs::exists(directory / k.image_file)) {
      throw InputError("map '" + directory.string() + "' is incomplete: key image '" +
                       (directory / k.image_file).string() + "' is missing");
    }
    map.key_images.push_back(std::move(k));
  }
  if (map.key_images.empty() && map.num_frames > 0) Malformed(file, "no key images");

  const json& links = doc.contains("links") ? doc["links"] : json();
  if (!links.is_array()) Malformed(file, "'links' is missing or not a list");
  const fs::path binary_file = directory / kCorrespondencesFileName;
  std::string binary;
  if (!links.empty()) {
    std::ifstream bin(binary_file, std::ios::binary);
    if (!bin) throw InputError("map '" + directory.string() + "' is incomplete: " + binary_file.string() + " is missing");
    binary.assign(std::istreambuf_iterator<char>(bin), std::istreambuf_iterator<char>());
  }
  const long records = static_cast<long>(binary.size() / (4 * sizeof(float)));
  for (size_t i = 0; i < links.size(); ++i) {
    const std::string where = "links[" + std::to_string(i) + "]";
    Link l;
    l.from_key = Field<int>(links[i], "from", file, where);
    l.to_key = Field<int>(links[i], "to", file, where);
    const int num_keys = static_cast<int>(map.key_images.size());
    if (l.from_key < 0 || l.from_key >= num_keys || l.to_key < 0 || l.to_key >= num_keys) {
      Malformed(file, where + " names a key image that does not exist");
    }
    // Schema version 1 called the flag `broken`.
    l.below_tau = links[i].contains("below_tau") ? links[i].value("below_tau", false) : links[i].value("broken", false);
    l.similarity = Field<double>(links[i], "similarity", file, where);
    l.num_tentative = Field<int>(links[i], "tentative", file, where);
    l.num_verified = Field<int>(links[i], "verified", file, where);
    const json& F = links[i].contains("F") ? links[i]["F"] : json();
    if (F.is_array() && F.size() == 9) {
      l.has_fundamental = true;
      for (int k = 0; k < 9; ++k) l.F(k / 3, k % 3) = F[k].get<double>();
    }
    const json& corr = links[i].contains("correspondences") ? links[i]["correspondences"] : json::object();
    const long offset = corr.value("offset", 0L);
    const long count = corr.value("count", 0L);
    if (offset < 0 || count < 0 || offset + count > records) {
      Malformed(binary_file, where + " correspondences [" + std::to_string(offset) + ", +" + std::to_string(count) +
                                 ") exceed the file's " + std::to_string(records) + " records");
    }
    if (l.num_verified > count) Malformed(file, where + " has more verified matches than correspondences");
    l.correspondences.resize(count);
    for (long r = 0; r < count; ++r) {
      float rec[4];
      std::memcpy(rec, binary.data() + (offset + r) * sizeof(rec), sizeof(rec));
      l.correspondences[r] = {{rec[0], rec[1]}, {rec[2], rec[3]}};
    }
    ReadLinkGeometryJson(links[i], l, file.string(), where);
    map.links.push_back(std::move(l));
  }

  if (doc.contains("evaluations")) {
    const json& ev = doc["evaluations"];
    try {
      const auto key_frame = ev.at("key_frame").get<std::vector<int>>();
      const auto frame = ev.at("frame").get<std::vector<int>>();
      const auto similarity = ev.at("similarity").get<std::vector<double>>();
      const auto tentative = ev.at("tentative").get<std::vector<int>>();
      const auto verified = ev.at("verified").get<std::vector<int>>();
      const auto matched = ev.at("matched").get<std::vector<bool>>();
      const size_t n = key_frame.size();
      if (frame.size() != n || similarity.size() != n || tentative.size() != n || verified.size() != n ||
          matched.size() != n) {
        Malformed(file, "'evaluations' columns have different lengths");
      }
      for (size_t i = 0; i < n; ++i) {
        map.evaluations.push_back({key_frame[i], frame[i], similarity[i], tentative[i], verified[i], matched[i]});
      }
    } catch (const json::exception&) {
      Malformed(file, "'evaluations' is not of the documented form");
    }
  }
  return map;
}

}  // namespace vmap
