#include "vmap/evaluation/evaluation_json.h"

#include <cmath>
#include <cstdint>
#include <optional>

#include <nlohmann/json.hpp>

#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/core/file_name_encoding.h"
#include "vmap/core/options_json.h"
#include "vmap/map/map_geometry_json.h"

namespace vmap {
using nlohmann::json;

namespace {

// A key every eval.json has: reading fails without it.
struct Required {};

// Each key of a link's object in eval.json with its field, once: EvaluationToJson writes through this list and
// ReadEvaluation reads through it, in this order. A third argument is what a file without the key (written by
// an earlier vmap) reads; otherwise the field keeps LinkEvaluation's default (numbers: NaN, written as null).
template <typename Visit>
void VisitLinkKeys(LinkEvaluation& e, Visit&& visit) {
  visit("link", e.link, Required());
  visit("from_frame", e.from_frame, Required());
  visit("to_frame", e.to_frame, Required());
  visit("from_source", e.from_source, e.from_frame);
  visit("to_source", e.to_source, e.to_frame);
  visit("below_tau", e.below_tau);
  visit("planar", e.planar);
  visit("similarity", e.similarity, 0.0);
  visit("verified", e.num_verified);
  visit("rejected", e.num_rejected);
  visit("has_ground_truth", e.has_ground_truth);
  visit("pose_source", e.pose_source, std::string("none"));
  visit("true_rotation_deg", e.true_rotation_deg);
  visit("true_baseline", e.true_baseline);
  visit("true_parallax_px", e.true_parallax_px);
  visit("rotation_error_deg", e.rotation_error_deg);
  visit("translation_error_deg", e.translation_error_deg);
  visit("true_pose_cost_excess", e.true_pose_cost_excess);
  visit("verified_sampson_median_px", e.verified_sampson_median);
  visit("verified_within_threshold", e.verified_within);
  visit("rejected_sampson_median_px", e.rejected_sampson_median);
  visit("rejected_within_threshold", e.rejected_within);
  visit("usable", e.usable);
  visit("consistent_matches", e.consistent_matches);
  visit("strict_usable", e.strict_usable);
  visit("translation_known", e.translation_known, e.pose_source == "stored");
  visit("translation_sigma_deg", e.translation_sigma_deg);
}

// The summary's keys, as VisitLinkKeys.
template <typename Visit>
void VisitSummaryKeys(EvaluationSummary& s, Visit&& visit) {
  visit("links", s.links);
  visit("evaluated_links", s.evaluated_links);
  visit("usable_links", s.usable_links);
  visit("usable_share", s.usable_share);
  visit("links_with_pose", s.links_with_pose);
  visit("rotation_error_deg_median", s.rotation_error_deg_median);
  visit("true_pose_cost_excess_median", s.true_pose_cost_excess_median);
  visit("translation_error_deg_median", s.translation_error_deg_median);
  visit("verified_within_threshold_mean", s.verified_within_mean);
  visit("rejected_within_threshold_mean", s.rejected_within_mean);
  visit("strict_usable_links", s.strict_usable_links);
  visit("strict_usable_share", s.strict_usable_share);
  visit("flagged_links", s.flagged_links);
  visit("flagged_wrong_links", s.flagged_wrong_links);
  visit("flagged_wrong_share", s.flagged_wrong_share);
  visit("unflagged_links", s.unflagged_links);
  visit("unflagged_right_links", s.unflagged_right_links);
  visit("unflagged_right_share", s.unflagged_right_share);
  visit("unflagged_usable_links", s.unflagged_usable_links);
  visit("unflagged_usable_share", s.unflagged_usable_share);
  visit("unflagged_reversed_links", s.unflagged_reversed_links);
}

// Writes the keys it visits into one JSON object; numbers that are not finite as null.
class KeyWriter {
 public:
  template <typename T, typename... Absent>
  void operator()(const char* key, const T& value, const Absent&...) {
    object_[key] = value;
  }
  template <typename... Absent>
  void operator()(const char* key, const double& value, const Absent&...) {
    object_[key] = std::isfinite(value) ? json(value) : json(nullptr);
  }
  json Take() { return std::move(object_); }

 private:
  json object_ = json::object();
};

// Reads the keys it visits from one JSON object: a value of another kind is a json::exception. A number without
// a value for a missing key reads as NaN where it is null, missing or not a number.
class KeyReader {
 public:
  explicit KeyReader(const json& object) : object_(object) {}

  template <typename T>
  void operator()(const char* key, T& value) {
    const auto it = object_.find(key);
    if (it != object_.end()) value = it->template get<T>();
  }
  template <typename T>
  void operator()(const char* key, T& value, Required) {
    value = object_.at(key).template get<T>();
  }
  template <typename T, typename Absent>
  void operator()(const char* key, T& value, const Absent& absent) {
    const auto it = object_.find(key);
    value = it != object_.end() ? it->template get<T>() : T(absent);
  }
  void operator()(const char* key, double& value) { value = Number(key); }

 private:
  double Number(const char* key) const {
    const auto it = object_.find(key);
    if (it == object_.end() || !it->is_number()) return NAN;
    return it->get<double>();
  }

  const json& object_;
};

}  // namespace

// The evaluation's layout: a reader of another refuses it, as one written before the version was checked (1 since the
// format began).
constexpr int kEvaluationSchemaVersion = 1;

std::string EvaluationToJson(const MapEvaluation& evaluation) {
  json doc;
  doc["format"] = "vmap-eval";
  doc["schema_version"] = kEvaluationSchemaVersion;
  doc["vmap_version"] = VMAP_VERSION;
  // Paths percent-encoded where they are not UTF-8, as in map.json (file_name_encoding.h).
  doc["map"] = EncodeFileName(evaluation.map_path);
  doc["ground_truth"] = {{"path", EncodeFileName(evaluation.ground_truth_path)},
                         {"format", GroundTruthFormatName(evaluation.ground_truth_format)}};
  doc["camera"] = CameraToJson(evaluation.camera);
  doc["options"] = OptionsToJson(evaluation.options);
  json links = json::array();
  for (LinkEvaluation e : evaluation.links) {  // a copy: the key list hands out fields by reference
    KeyWriter writer;
    VisitLinkKeys(e, writer);
    links.push_back(writer.Take());
  }
  doc["links"] = std::move(links);
  EvaluationSummary summary = evaluation.summary;
  KeyWriter writer;
  VisitSummaryKeys(summary, writer);
  doc["summary"] = writer.Take();
  return doc.dump(1) + "\n";
}

MapEvaluation ReadEvaluation(const std::string& path) {
  std::string why_not;
  const std::optional<ContainedFile> file = ContainedFile::OpenRegular(path, &why_not);
  if (!file) throw InputError("evaluation '" + path + "' " + why_not + "; run `vmap eval` again");
  // Some 25 values a link.
  constexpr std::uint64_t kMaxValues = 1ull << 24;
  json doc;
  why_not = file->ParseJson(kMaxValues, &doc);
  if (!why_not.empty()) throw InputError("evaluation '" + path + "' " + why_not + "; run `vmap eval` again");
  if (!doc.is_object() || doc.value("format", "") != "vmap-eval" || !doc.contains("links") ||
      !doc["links"].is_array() || !doc.contains("summary") || !doc["summary"].is_object()) {
    throw InputError("'" + path + "' is not an evaluation written by `vmap eval`; run `vmap eval` again");
  }
  if (!doc.contains("schema_version") || !doc["schema_version"].is_number_integer() ||
      doc["schema_version"].get<std::int64_t>() != kEvaluationSchemaVersion) {
    throw InputError("evaluation '" + path + "' is of schema version " + doc.value("schema_version", json()).dump() +
                     ", which this vmap does not read (it reads " + std::to_string(kEvaluationSchemaVersion) +
                     "); run `vmap eval` again");
  }
  MapEvaluation evaluation;
  try {
    evaluation.map_path = DecodeFileName(doc.value("map", ""));
    const json& gt = doc.contains("ground_truth") ? doc["ground_truth"] : json::object();
    evaluation.ground_truth_path = DecodeFileName(gt.value("path", ""));
    evaluation.ground_truth_format = ParseGroundTruthFormat(gt.value("format", "auto"));
    if (doc.contains("camera") && doc["camera"].is_object()) {
      evaluation.camera = CameraFromJson(doc["camera"], path, "camera");
    }
    const json& options = doc.contains("options") ? doc["options"] : json::object();
    OptionsFromJson(JsonFieldReader(options, "evaluation '" + path + "': options"), &evaluation.options);
    for (const json& l : doc["links"]) {
      LinkEvaluation e;
      VisitLinkKeys(e, KeyReader(l));
      evaluation.links.push_back(e);
    }
    VisitSummaryKeys(evaluation.summary, KeyReader(doc["summary"]));
  } catch (const json::exception& e) {
    throw InputError("evaluation '" + path + "' is malformed (" + e.what() + "); run `vmap eval` again");
  }
  return evaluation;
}

}  // namespace vmap
