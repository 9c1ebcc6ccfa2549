#include "vmap/features/matcher_options_json.h"

#include <filesystem>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "vmap/core/error.h"

namespace vmap {

namespace {

template <typename T>
void Read(const nlohmann::json& object, const char* name, T& value, const std::string& map_file) {
  auto it = object.find(name);
  if (it == object.end() || it->is_null()) return;
  try {
    value = it->get<T>();
  } catch (const nlohmann::json::exception&) {
    throw InputError("map '" + map_file + "': options.matcher." + name + " has the wrong type; rebuild the map");
  }
}

// The weights file recorded where the map was built may not exist here: search the weights directories.
void SearchWeightsWhenMissing(const char* model, std::string& weights) {
  if (weights.empty() || std::filesystem::exists(weights)) return;
  spdlog::info("the map's {} weights '{}' are not here; searching the weights directories", model, weights);
  weights.clear();
}

}  // namespace

MatcherOptions MatcherOptionsFromJson(const std::string& matcher_json, const std::string& map_file) {
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(matcher_json);
  } catch (const nlohmann::json::exception&) {
    throw InputError("map '" + map_file + "': options.matcher is not valid JSON; rebuild the map");
  }
  if (!doc.is_object() || !doc.contains("type") || !doc["type"].is_string()) {
    throw InputError("map '" + map_file + "' does not record its matcher (options.matcher.type); rebuild it with "
                     "this vmap");
  }
  MatcherOptions options;
  options.type = doc["type"].get<std::string>();
  if (options.type == "orb") {
    OrbMatcherOptions& orb = options.orb;
    Read(doc, "num_features", orb.num_features, map_file);
    Read(doc, "scale_factor", orb.scale_factor, map_file);
    Read(doc, "num_levels", orb.num_levels, map_file);
    Read(doc, "edge_threshold", orb.edge_threshold, map_file);
    Read(doc, "fast_threshold", orb.fast_threshold, map_file);
    Read(doc, "cross_check", orb.cross_check, map_file);
    Read(doc, "ratio", orb.ratio, map_file);
  } else if (options.type == "loftr") {
    LoftrMatcherOptions& loftr = options.loftr;
    Read(doc, "model", loftr.model, map_file);
    Read(doc, "weights", loftr.weights, map_file);
    Read(doc, "device", loftr.device, map_file);
    Read(doc, "longest_side", loftr.longest_side, map_file);
    Read(doc, "threshold", loftr.threshold, map_file);
    Read(doc, "threads", loftr.num_threads, map_file);
    SearchWeightsWhenMissing("LoFTR", loftr.weights);
  } else if (options.type == "xfeat") {
    XfeatMatcherOptions& xfeat = options.xfeat;
    Read(doc, "weights", xfeat.weights, map_file);
    Read(doc, "device", xfeat.device, map_file);
    Read(doc, "top_k", xfeat.top_k, map_file);
    Read(doc, "detection_threshold", xfeat.detection_threshold, map_file);
    Read(doc, "min_similarity", xfeat.min_similarity, map_file);
    Read(doc, "threads", xfeat.num_threads, map_file);
    SearchWeightsWhenMissing("XFeat", xfeat.weights);
  } else if (options.type == "aliked") {
    AlikedMatcherOptions& aliked = options.aliked;
    Read(doc, "model", aliked.model, map_file);
    if (aliked.model.rfind("aliked-", 0) == 0) aliked.model = aliked.model.substr(7);  // recorded as aliked-t16
    Read(doc, "weights", aliked.weights, map_file);
    Read(doc, "device", aliked.device, map_file);
    Read(doc, "top_k", aliked.top_k, map_file);
    Read(doc, "score_threshold", aliked.score_threshold, map_file);
    Read(doc, "max_keypoints", aliked.max_keypoints, map_file);
    Read(doc, "min_similarity", aliked.min_similarity, map_file);
    Read(doc, "longest_side", aliked.longest_side, map_file);
    Read(doc, "threads", aliked.num_threads, map_file);
    SearchWeightsWhenMissing("ALIKED", aliked.weights);
  } else {
    throw InputError("map '" + map_file + "' was built with the matcher '" + options.type +
                     "', which this vmap cannot create; use a vmap that has it");
  }
  options.Check();
  return options;
}

}  // namespace vmap
