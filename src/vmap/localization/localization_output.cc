#include "vmap/localization/localization_output.h"

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/core/file_name_encoding.h"
#include "vmap/core/options_json.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {
using nlohmann::json;

int KeyFrame(const VisualMap& map, int key) {
  return key >= 0 && key < static_cast<int>(map.key_images.size()) ? map.key_images[key].frame_index : -1;
}

// NaN and infinity are unknown: null in JSON.
json Number(double value) { return std::isfinite(value) ? json(value) : json(nullptr); }

std::string CsvNumber(double value) { return std::isfinite(value) ? fmt::format("{:.6g}", value) : std::string(); }

// A CSV field: quoted when it holds a separator, a quote or a line break.
std::string CsvText(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  return quoted + "\"";
}

LocalizationStatus ParseStatus(const std::string& name, const std::filesystem::path& file) {
  if (const std::optional<LocalizationStatus> status = FindEnum(kLocalizationStatusNames, name)) return *status;
  throw InputError("'" + file.string() + "' has a frame with the unknown status '" + name + "'");
}

double NumberOr(const json& object, const char* name, double fallback) {
  auto it = object.find(name);
  return it != object.end() && it->is_number() ? it->get<double>() : fallback;
}

// A run's file, and where in it a field is (`frames[3]`), for the messages of a run that was edited.
struct RunPlace {
  const std::filesystem::path& file;
  std::string where;
  [[noreturn]] void Refuse(const char* name, const std::string& must) const {
    const std::string field = *name == '\0' ? where : where.empty() ? std::string(name) : where + "." + name;
    throw InputError(
        fmt::format("'{}': {} {}; write it again with `vmap localize --json`", file.string(), field, must));
  }
};

// An integer of a run (a frame or key image index, a count) named `name`: one an int holds (not 2^31, which would wrap
// to a negative index, nor 0.5 or true).
int IntOf(const json& value, const char* name, const RunPlace& place) {
  const bool fits = value.is_number_unsigned()  ? value.get<std::uint64_t>() <= std::numeric_limits<int>::max()
                    : value.is_number_integer() ? value.get<std::int64_t>() >= std::numeric_limits<int>::min() &&
                                                      value.get<std::int64_t>() <= std::numeric_limits<int>::max()
                                                : false;
  if (!fits) place.Refuse(name, "must be a whole number from -2147483648 to 2147483647, and is " + value.dump());
  return value.get<int>();
}

// An integer field of a run: `fallback` when absent or null.
int IntOr(const json& object, const char* name, int fallback, const RunPlace& place) {
  const auto it = object.find(name);
  return it == object.end() || it->is_null() ? fallback : IntOf(*it, name, place);
}

// A text field of a run: `fallback` when absent or null.
std::string TextOr(const json& object, const char* name, const std::string& fallback, const RunPlace& place) {
  const auto it = object.find(name);
  if (it == object.end() || it->is_null()) return fallback;
  if (!it->is_string()) place.Refuse(name, "must be a string, and is " + it->dump());
  return it->get<std::string>();
}

// The pose to the key image the heading is measured against: next_key's, or key's at the route's end.
const RelativePose& TargetPose(const LocalizationResult& r) { return r.next_key >= 0 ? r.to_next.pose : r.to_key.pose; }
// The confidence of the heading against that key image (the one heading_px reports), and against `key`; NaN
// (unknown) without an estimate.
double Confidence(const HeadingEstimate& h) { return h.valid() ? h.confidence : std::nan(""); }
double TargetConfidence(const LocalizationResult& r) {
  return Confidence(r.next_key >= 0 ? r.to_next.heading : r.to_key.heading);
}

json PoseJson(const RelativePose& pose) {
  if (!pose.valid) return nullptr;
  json R = json::array();
  for (int i = 0; i < 9; ++i) R.push_back(pose.R(i / 3, i % 3));
  return {{"R", R}, {"t", {pose.t[0], pose.t[1], pose.t[2]}}};
}

}  // namespace

std::string DescribeLocalizerOptions(const LocalizerOptions& options) { return OptionsToJson(options).dump(); }

std::string LocalizationCsvHeader(bool experiences) {
  return std::string(
             "frame,source_index,timestamp,source_name,status,key,next_key,key_frame,next_key_frame,similarity,"
             "verified,"
             "tentative,next_similarity,next_verified,next_tentative,heading_px,progress,comparisons,seconds,"
             "F00,F01,F02,F10,F11,F12,F20,F21,F22,heading_deg,R00,R01,R02,R10,R11,R12,R20,R21,R22,tx,ty,tz,"
             "heading_confidence,heading_key_px,heading_key_deg,heading_key_confidence,"
             "translation_sigma_deg,translation_known,guidance,"
             "log10_nfa,next_log10_nfa") +
         (experiences ? ",experience,next_experience" : "") + ",confidence,key_rank\n";
}

std::string LocalizationCsvRow(const VisualMap& map, const LocalizationResult& r, bool experiences) {
  std::string row = fmt::format(
      "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{:.6f}", r.frame_index, r.source_index,
      r.timestamp >= 0 ? fmt::format("{:.6f}", r.timestamp) : std::string(), CsvText(EncodeFileName(r.source_name)),
      LocalizationStatusName(r.status), r.key, r.next_key, KeyFrame(map, r.key), KeyFrame(map, r.next_key),
      r.to_key.key >= 0 ? CsvNumber(r.to_key.similarity) : "", r.to_key.num_verified, r.to_key.num_tentative,
      r.to_next.key >= 0 ? CsvNumber(r.to_next.similarity) : "", r.to_next.num_verified, r.to_next.num_tentative,
      CsvNumber(r.heading_px), CsvNumber(r.progress), r.comparisons, r.seconds);
  for (int i = 0; i < 9; ++i) {
    row += ',';
    if (r.to_next.matched) row += fmt::format("{:.9g}", r.to_next.F(i / 3, i % 3));
  }
  row += ',' + CsvNumber(r.heading_deg);
  const RelativePose& pose = TargetPose(r);
  for (int i = 0; i < 9; ++i) row += ',' + (pose.valid ? fmt::format("{:.9g}", pose.R(i / 3, i % 3)) : std::string());
  for (int i = 0; i < 3; ++i) row += ',' + (pose.valid ? fmt::format("{:.9g}", pose.t[i]) : std::string());
  row += ',' + CsvNumber(TargetConfidence(r)) + ',' + CsvNumber(r.heading_key_px) + ',' + CsvNumber(r.heading_key_deg) +
         ',' + CsvNumber(Confidence(r.to_key.heading));
  const KeyComparison& target = r.next_key >= 0 ? r.to_next : r.to_key;
  row += ',' + (pose.valid ? CsvNumber(target.translation_sigma_deg) : std::string());
  row += fmt::format(",{},{}", r.translation_known ? 1 : 0, LocalizationGuidance(r));
  row += ',' + CsvNumber(r.to_key.log10_nfa) + ',' + CsvNumber(r.to_next.log10_nfa);
  if (experiences) {
    row += ',' + (r.to_key.key >= 0 ? std::to_string(r.to_key.experience) : std::string()) + ',' +
           (r.to_next.key >= 0 ? std::to_string(r.to_next.experience) : std::string());
  }
  row += ',' + CsvNumber(r.confidence) + ',' + std::to_string(r.key_rank);
  return row + "\n";
}

nlohmann::json LocalizationFrameJson(const VisualMap& map, const LocalizationResult& r, bool experiences) {
  json F = nullptr;
  if (r.to_next.matched) {
    F = json::array();
    for (int i = 0; i < 9; ++i) F.push_back(r.to_next.F(i / 3, i % 3));
  }
  json candidates = json::array();
  for (const RelocalizationCandidate& c : r.candidates) {
    candidates.push_back({{"key", c.key},
                          {"score", c.score},
                          {"accepted", c.accepted},
                          {"similarity", c.similarity},
                          {"verified", c.num_verified},
                          {"log10_nfa", Number(c.log10_nfa)}});
  }
  json frame = {
      {"frame", r.frame_index},
      {"source_index", r.source_index},
      {"timestamp", r.timestamp >= 0 ? json(r.timestamp) : json(nullptr)},
      {"source_name", EncodeFileName(r.source_name)},
      {"status", LocalizationStatusName(r.status)},
      {"withheld_by", r.withheld_by == Withholding::kNone ? json(nullptr) : json(WithholdingName(r.withheld_by))},
      {"key", r.key},
      {"next_key", r.next_key},
      {"key_frame", KeyFrame(map, r.key)},
      {"next_key_frame", KeyFrame(map, r.next_key)},
      {"similarity", r.to_key.key >= 0 ? Number(r.to_key.similarity) : json(nullptr)},
      {"verified", r.to_key.num_verified},
      {"tentative", r.to_key.num_tentative},
      {"next_similarity", r.to_next.key >= 0 ? Number(r.to_next.similarity) : json(nullptr)},
      {"next_verified", r.to_next.num_verified},
      {"next_tentative", r.to_next.num_tentative},
      {"log10_nfa", Number(r.to_key.log10_nfa)},
      {"next_log10_nfa", Number(r.to_next.log10_nfa)},
      {"heading_px", Number(r.heading_px)},
      {"heading_deg", Number(r.heading_deg)},
      {"heading_confidence", Number(TargetConfidence(r))},
      {"heading_key_px", Number(r.heading_key_px)},
      {"heading_key_deg", Number(r.heading_key_deg)},
      {"heading_key_confidence", Number(Confidence(r.to_key.heading))},
      {"pose", PoseJson(TargetPose(r))},
      {"translation_sigma_deg",
       TargetPose(r).valid ? Number((r.next_key >= 0 ? r.to_next : r.to_key).translation_sigma_deg) : json(nullptr)},
      {"translation_known", r.translation_known},
      {"guidance", LocalizationGuidance(r)},
      {"progress", Number(r.progress)},
      {"F", F},
      {"candidates", candidates},
      {"comparisons", r.comparisons},
      {"seconds", r.seconds}};
  if (experiences) {
    frame["experience"] = r.to_key.key >= 0 ? json(r.to_key.experience) : json(nullptr);
    frame["next_experience"] = r.to_next.key >= 0 ? json(r.to_next.experience) : json(nullptr);
  }
  frame["confidence"] = Number(r.confidence);
  frame["key_rank"] = r.key_rank;
  frame["motion_steps"] = r.motion_steps;
  json belief = json::array();
  for (const auto& [key, mass] : r.belief) belief.push_back({key, mass});
  frame["belief"] = belief;
  return frame;
}

std::string LocalizationRunJson(const VisualMap& map, const LocalizationRun& run) {
  const LocalizationRunInfo& info = run.info;
  const LocalizationSummary& s = run.summary;
  json doc;
  doc["format"] = "vmap-localization";
  doc["schema_version"] = kLocalizationSchemaVersion;
  doc["vmap_version"] = VMAP_VERSION;
  // Paths percent-encoded where they are not UTF-8, as in map.json (file_name_encoding.h).
  const auto absolute = [](const std::string& path) {
    std::error_code ec;
    const std::string made = path.empty() ? "" : fs::absolute(path, ec).lexically_normal().string();
    return ec ? path : made;
  };
  doc["map"] = {{"directory", EncodeFileName(info.map_directory)},
                {"absolute_directory", EncodeFileName(absolute(info.map_directory))},
                {"key_images", map.key_images.size()},
                {"matcher", info.matcher},
                {"input", EncodeFileName(map.input.path)}};
  doc["query"] = {{"path", EncodeFileName(info.query)},
                  {"absolute_path", EncodeFileName(absolute(info.query))},
                  {"format", SourceFormatName(info.query_format)},
                  {"first", info.source.first},
                  {"last", info.source.last},
                  {"stride", info.source.stride},
                  {"resize", info.source.resize},
                  {"topic", info.source.topic},
                  {"camera_topic", info.source.camera_topic},
                  {"frame_size", {info.frame_size.width, info.frame_size.height}}};
  doc["ranking"] = info.ranking;
  doc["key_image_cache"] = info.cache;
  doc["key_image_seconds"] = info.key_image_seconds;
  doc["options"] = json::parse(info.options_json.empty() ? "{}" : info.options_json);
  const double n = s.frames > 0 ? static_cast<double>(s.frames) : 1.0;
  doc["summary"] = {{"frames", s.frames},
                    {"tracking", s.tracking},
                    {"relocalized", s.relocalized},
                    {"lost", s.lost},
                    {"uncertain", s.uncertain},
                    {"share_tracking", s.tracking / n},
                    {"share_relocalized", s.relocalized / n},
                    {"share_lost", s.lost / n},
                    {"share_uncertain", s.uncertain / n},
                    {"skipped_frames", s.skipped_frames},
                    {"seconds", s.seconds},
                    {"frames_per_second", s.frames_per_second},
                    {"mean_localize_seconds", s.mean_localize_seconds},
                    {"max_localize_seconds", s.max_localize_seconds},
                    {"mean_extract_seconds", s.mean_extract_seconds},
                    {"comparisons", s.comparisons}};
  json frames = json::array();
  for (const LocalizationResult& r : run.frames) frames.push_back(LocalizationFrameJson(map, r, info.experiences));
  doc["frames"] = std::move(frames);
  return doc.dump(1) + "\n";
}

LocalizationRun ReadLocalizationRun(const std::filesystem::path& file) {
  std::string why_not;
  const std::optional<ContainedFile> opened = ContainedFile::OpenRegular(file, &why_not);
  if (!opened) throw InputError("'" + file.string() + "' " + why_not + "; give the --json file of `vmap localize`");
  if (opened->size() > kMaxRunJsonBytes) {
    throw InputError("'" + file.string() +
                     "' is larger than any localization run; give the --json file of "
                     "`vmap localize`");
  }
  json doc;
  why_not = opened->ParseJson(kMaxRunJsonValues, &doc);
  if (!why_not.empty()) {
    throw InputError("'" + file.string() + "' " + why_not + "; give the --json file of `vmap localize`");
  }
  const RunPlace top{file, ""};
  // Compared as JSON: a format of another kind is simply not this one.
  if (!doc.is_object() || !doc.contains("format") || doc["format"] != "vmap-localization") {
    throw InputError("'" + file.string() + "' is not a localization run (no format \"vmap-localization\")");
  }
  if (IntOr(doc, "schema_version", 0, top) > kLocalizationSchemaVersion) {
    throw InputError("'" + file.string() + "' was written by a newer vmap; update vmap");
  }
  LocalizationRun run;
  try {
    const json& map = doc.at("map");
    run.info.map_directory = DecodeFileName(TextOr(map, "directory", "", RunPlace{file, "map"}));
    run.info.map_absolute_directory = DecodeFileName(TextOr(map, "absolute_directory", "", RunPlace{file, "map"}));
    run.info.matcher = TextOr(map, "matcher", "", RunPlace{file, "map"});
    run.recorded_map.key_images = IntOr(map, "key_images", -1, RunPlace{file, "map"});
    const json& query = doc.at("query");
    run.info.query = DecodeFileName(TextOr(query, "path", "", RunPlace{file, "query"}));
    run.info.query_absolute_path = DecodeFileName(TextOr(query, "absolute_path", "", RunPlace{file, "query"}));
    run.info.query_format = ParseSourceFormat(TextOr(query, "format", "auto", RunPlace{file, "query"}));
    // Read as ints are (IntOf): 4294967299 wrapped to 3 and 1e12 to a negative frame, named by no file or field.
    const RunPlace in_query{file, "query"};
    run.info.source.first = IntOr(query, "first", 0, in_query);
    run.info.source.last = IntOr(query, "last", -1, in_query);
    run.info.source.stride = IntOr(query, "stride", 1, in_query);
    run.info.source.resize = TextOr(query, "resize", "", in_query);
    run.info.source.topic = TextOr(query, "topic", "", in_query);
    run.info.source.camera_topic = TextOr(query, "camera_topic", "", in_query);
    if (query.contains("frame_size") && query["frame_size"].size() == 2) {
      run.info.frame_size = {IntOf(query["frame_size"][0], "frame_size", in_query),
                             IntOf(query["frame_size"][1], "frame_size", in_query)};
    }
    run.info.ranking = doc.value("ranking", "");
    run.info.cache = doc.value("key_image_cache", "");
    run.info.key_image_seconds = doc.value("key_image_seconds", 0.0);
    run.info.options_json = doc.contains("options") ? doc["options"].dump() : "{}";
    const json& s = doc.at("summary");
    run.summary.frames = s.value("frames", 0L);
    run.summary.tracking = s.value("tracking", 0L);
    run.summary.relocalized = s.value("relocalized", 0L);
    run.summary.lost = s.value("lost", 0L);
    run.summary.uncertain = s.value("uncertain", 0L);
    run.summary.skipped_frames = s.value("skipped_frames", 0);
    run.summary.seconds = s.value("seconds", 0.0);
    run.summary.frames_per_second = s.value("frames_per_second", 0.0);
    run.summary.mean_localize_seconds = s.value("mean_localize_seconds", 0.0);
    run.summary.max_localize_seconds = s.value("max_localize_seconds", 0.0);
    run.summary.mean_extract_seconds = s.value("mean_extract_seconds", 0.0);
    run.summary.comparisons = s.value("comparisons", 0L);
    const json& frames = doc.at("frames");
    if (!frames.is_array()) top.Refuse("frames", "must be a list");
    for (size_t i = 0; i < frames.size(); ++i) {
      const json& f = frames[i];
      const RunPlace place{file, fmt::format("frames[{}]", i)};
      if (!f.is_object()) place.Refuse("", "must be an object");
      LocalizationResult r;
      if (!f.contains("frame")) place.Refuse("frame", "is missing");
      r.frame_index = IntOr(f, "frame", -1, place);
      r.source_index = IntOr(f, "source_index", r.frame_index, place);
      r.timestamp = NumberOr(f, "timestamp", -1.0);
      r.source_name = DecodeFileName(f.value("source_name", ""));
      r.status = ParseStatus(f.at("status").get<std::string>(), file);
      // Runs written before the rules were named have none.
      if (f.contains("withheld_by") && f["withheld_by"].is_string()) {
        r.withheld_by = FindEnum(kWithholdingNames, f["withheld_by"].get<std::string>()).value_or(Withholding::kNone);
      }
      r.key = IntOr(f, "key", -1, place);
      r.next_key = IntOr(f, "next_key", -1, place);
      r.to_key.key = r.key;
      r.to_key.similarity = NumberOr(f, "similarity", 0.0);
      r.to_key.num_verified = IntOr(f, "verified", 0, place);
      r.to_key.num_tentative = IntOr(f, "tentative", 0, place);
      r.to_next.key = r.next_key;
      r.to_next.similarity = NumberOr(f, "next_similarity", 0.0);
      r.to_next.num_verified = IntOr(f, "next_verified", 0, place);
      r.to_next.num_tentative = IntOr(f, "next_tentative", 0, place);
      // A map with experiences names the view compared (0: the key image itself); a report draws it.
      r.to_key.experience = IntOr(f, "experience", 0, place);
      r.to_next.experience = IntOr(f, "next_experience", 0, place);
      r.translation_known = f.value("translation_known", false);
      r.to_key.log10_nfa = NumberOr(f, "log10_nfa", std::numeric_limits<double>::infinity());
      r.to_next.log10_nfa = NumberOr(f, "next_log10_nfa", std::numeric_limits<double>::infinity());
      if (f.contains("F") && f["F"].is_array() && f["F"].size() == 9) {
        r.to_next.matched = true;
        for (int i = 0; i < 9; ++i) r.to_next.F(i / 3, i % 3) = f["F"][i].get<double>();
      }
      r.heading_px = NumberOr(f, "heading_px", std::nan(""));
      r.heading_deg = NumberOr(f, "heading_deg", std::nan(""));
      r.heading_key_px = NumberOr(f, "heading_key_px", std::nan(""));
      r.heading_key_deg = NumberOr(f, "heading_key_deg", std::nan(""));
      r.progress = NumberOr(f, "progress", std::nan(""));
      if (f.contains("candidates") && f["candidates"].is_array()) {
        for (const json& c : f["candidates"]) {
          r.candidates.push_back({IntOr(c, "key", -1, place), c.value("score", 0.0), c.value("accepted", false),
                                  c.value("similarity", 0.0), IntOr(c, "verified", 0, place),
                                  NumberOr(c, "log10_nfa", std::numeric_limits<double>::infinity())});
        }
      }
      r.comparisons = IntOr(f, "comparisons", 0, place);
      r.seconds = f.value("seconds", 0.0);
      r.confidence = NumberOr(f, "confidence", std::nan(""));
      r.key_rank = IntOr(f, "key_rank", -1, place);
      r.motion_steps = IntOr(f, "motion_steps", 0, place);
      if (f.contains("belief") && f["belief"].is_array()) {
        for (const json& b : f["belief"]) {
          if (!b.is_array() || b.size() != 2) place.Refuse("belief", "must be a list of [key, mass] pairs");
          r.belief.emplace_back(IntOf(b[0], "belief's key", place), b.at(1).get<double>());
        }
      }
      run.frames.push_back(std::move(r));
      // Runs written before key_frame was recorded have none to check.
      if (f.contains("key_frame") && f.contains("next_key_frame")) {
        run.recorded_map.key_frames.emplace_back(
            std::make_pair(IntOr(f, "key_frame", -1, place), IntOr(f, "next_key_frame", -1, place)));
      } else {
        run.recorded_map.key_frames.emplace_back();
      }
    }
  } catch (const json::exception&) {
    throw InputError("'" + file.string() +
                     "' is not of the documented form of a localization run; write it again "
                     "with `vmap localize --json`");
  }
  return run;
}

void CheckRunFitsMap(const LocalizationRun& run, const VisualMap& map, const std::filesystem::path& file) {
  const int num_keys = static_cast<int>(map.key_images.size());
  for (const LocalizationResult& r : run.frames) {
    std::vector<int> keys = {r.key, r.next_key};
    for (const RelocalizationCandidate& c : r.candidates) keys.push_back(c.key);
    for (int key : keys) {
      if (key >= -1 && key < num_keys) continue;
      throw InputError(
          fmt::format("'{}': frame {} names key image {}, and its map '{}' has key images 0 to {}: the run "
                      "is of another map, or was edited; localize again with `vmap localize --json`",
                      file.string(), r.frame_index, key, run.info.map_directory, num_keys - 1));
    }
  }
  const RunMapRecord& recorded = run.recorded_map;
  if (recorded.key_images >= 0 && recorded.key_images != num_keys) {
    throw InputError(
        fmt::format("'{}' was made against the map '{}' when it had {} key images, and it has {} now: "
                    "the map was built again since; localize again with `vmap localize --json`",
                    file.string(), run.info.map_directory, recorded.key_images, num_keys));
  }
  for (size_t i = 0; i < run.frames.size() && i < recorded.key_frames.size(); ++i) {
    if (!recorded.key_frames[i]) continue;
    const LocalizationResult& r = run.frames[i];
    const std::pair<int, int> now(KeyFrame(map, r.key), KeyFrame(map, r.next_key));
    if (now == *recorded.key_frames[i]) continue;
    const bool key_moved = now.first != recorded.key_frames[i]->first;
    throw InputError(fmt::format(
        "'{}': frame {} was localized at {} key image {}, map frame {}, and key image {} of the map '{}' is map "
        "frame {} now: the map was built again since; localize again with `vmap localize --json`",
        file.string(), r.frame_index, key_moved ? "the" : "the next", key_moved ? r.key : r.next_key,
        key_moved ? recorded.key_frames[i]->first : recorded.key_frames[i]->second, key_moved ? r.key : r.next_key,
        run.info.map_directory, key_moved ? now.first : now.second));
  }
}

}  // namespace vmap
