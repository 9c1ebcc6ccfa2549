// WriteMapFiles and its parts: map.json (its evaluations streamed column by column) and correspondences.bin.
// Reading them back, with every check an untrusted map needs, is map_io.cc.
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "vmap/core/atomic_output.h"
#include "vmap/core/file_name_encoding.h"
#include "vmap/map/map_geometry_json.h"
#include "vmap/map/map_io.h"
#include "vmap/sources/frame_source.h"

namespace vmap {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

json TimestampJson(double t) { return t < 0 ? json(nullptr) : json(t); }

json SizeJson(const cv::Size& s) { return json::array({s.width, s.height}); }

json MapDocument(const VisualMap& map, const std::vector<long>& offsets, bool with_evaluations = true) {
  json doc;
  doc["format"] = "vmap-map";
  doc["schema_version"] = kMapSchemaVersion;
  doc["vmap_version"] = VMAP_VERSION;
  doc["input"] = {{"path", EncodeFileName(map.input.path)},
                  {"format", SourceFormatName(map.input.format)},
                  {"native_size", SizeJson(map.input.native_size)},
                  {"frame_size", SizeJson(map.input.frame_size)},
                  {"fps", map.input.fps}};
  if (!map.input.absolute_path.empty()) doc["input"]["absolute_path"] = EncodeFileName(map.input.absolute_path);
  doc["input"]["camera"] = map.input.camera ? CameraToJson(*map.input.camera) : json(nullptr);
  if (!map.camera_mask.empty()) doc["input"]["camera_mask"] = kCameraMaskFileName;
  doc["conventions"] = MapConventionsJson();
  doc["options"] = map.options_json.empty() ? json::object() : json::parse(map.options_json);
  doc["num_frames"] = map.num_frames;
  doc["skipped_frames"] = map.skipped_frames;
  doc["num_key_images"] = map.key_images.size();
  doc["quality"] = map.quality;
  doc["seconds"] = map.seconds;
  if (map.coverage) {
    doc["coverage"] = {{"frames", map.coverage->num_frames},
                       {"first_source_index", map.coverage->first_source_index},
                       {"last_source_index", map.coverage->last_source_index},
                       {"end", CoverageEndName(map.coverage->end)}};
  }
  json keys = json::array();
  for (const KeyImage& k : map.key_images) {
    keys.push_back({{"frame_index", k.frame_index},
                    {"source_index", k.source_index},
                    {"timestamp", TimestampJson(k.timestamp)},
                    {"source_name", EncodeFileName(k.source_name)},
                    {"image", EncodeFileName(k.image_file)},
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
  if (!map.experiences.empty()) doc["experiences"] = ExperiencesToJson(map.experiences);
  if (!with_evaluations) return doc;
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

}  // namespace

std::string MapToJson(const VisualMap& map) { return MapDocument(map, CorrespondenceOffsets(map)).dump(1); }

std::string CoverageEndName(CoverageEnd end) { return EnumToName(kCoverageEndNames, end); }

namespace {

// One column of the evaluations, as nlohmann's dump(1) writes an array two levels down.
template <typename Value>
void WriteEvaluationColumn(std::ostream& out, const EvaluationSource& evaluations, Value value) {
  bool first = true;
  out << "[";
  evaluations([&](const Evaluation& e) {
    out << (first ? "\n   " : ",\n   ") << value(e);
    first = false;
  });
  out << (first ? "]" : "\n  ]");
}

}  // namespace

void WriteMapJson(std::ostream& out, const VisualMap& map, const EvaluationSource& streamed) {
  json doc = MapDocument(map, CorrespondenceOffsets(map), /*with_evaluations=*/false);
  // The evaluations are written in place of a marker, column by column, exactly as dump(1) writes them (a test
  // compares the two); "evaluations" sorts before every key whose value a user controls ("input", "options").
  const std::string marker = "\x01vmap evaluations\x01";
  doc["evaluations"] = marker;
  const std::string text = doc.dump(1);
  const size_t at = text.find(json(marker).dump());
  const EvaluationSource evaluations = streamed ? streamed : [&map](const std::function<void(const Evaluation&)>& fn) {
    for (const Evaluation& e : map.evaluations) fn(e);
  };
  out.write(text.data(), static_cast<std::streamsize>(at));
  // Keys in nlohmann's (alphabetical) order.
  out << "{\n  \"frame\": ";
  WriteEvaluationColumn(out, evaluations, [](const Evaluation& e) { return e.frame; });
  out << ",\n  \"key_frame\": ";
  WriteEvaluationColumn(out, evaluations, [](const Evaluation& e) { return e.key_frame; });
  out << ",\n  \"matched\": ";
  WriteEvaluationColumn(out, evaluations, [](const Evaluation& e) { return e.matched ? "true" : "false"; });
  out << ",\n  \"similarity\": ";
  WriteEvaluationColumn(out, evaluations, [](const Evaluation& e) { return json(e.similarity).dump(); });
  out << ",\n  \"tentative\": ";
  WriteEvaluationColumn(out, evaluations, [](const Evaluation& e) { return e.num_tentative; });
  out << ",\n  \"verified\": ";
  WriteEvaluationColumn(out, evaluations, [](const Evaluation& e) { return e.num_verified; });
  out << "\n }";
  const size_t after = at + json(marker).dump().size();
  out.write(text.data() + after, static_cast<std::streamsize>(text.size() - after));
  out << "\n";
}

std::string CorrespondencesBinary(const VisualMap& map) {
  std::string binary;
  for (const Link& l : map.links) {
    for (const Correspondence& c : l.correspondences) {
      const float record[4] = {c.p0.x, c.p0.y, c.p1.x, c.p1.y};
      binary.append(reinterpret_cast<const char*>(record), sizeof(record));  // x86/ARM: little-endian
    }
  }
  return binary;
}

void WriteCameraMask(const VisualMap& map, const fs::path& directory) {
  if (map.camera_mask.empty()) return;
  std::vector<uchar> png;
  cv::imencode(".png", map.camera_mask, png);
  WriteFileAtomically(directory / kCameraMaskFileName, std::string(png.begin(), png.end()));
}

void WriteMapFiles(const VisualMap& map, const fs::path& directory) {
  WriteCameraMask(map, directory);
  WriteFileAtomically(directory / kCorrespondencesFileName, CorrespondencesBinary(map));
  std::ostringstream text;
  WriteMapJson(text, map);
  WriteFileAtomically(directory / kMapFileName, text.str());
}

}  // namespace vmap
