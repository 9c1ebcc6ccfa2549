#pragma once
// What a map records of the options that shaped it (map.json's "options"), typed.

#include <filesystem>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "vmap/map/visual_map.h"
#include "vmap/mapping/map_builder_options.h"
#include "vmap/sources/frame_source.h"

namespace vmap {

// Every option that shaped a map: map.json's "options" (sweep.json's for a sweep), the builder's and the
// input's typed, the matcher's as the matcher describes itself (a model's record may hold derived values;
// features/matcher_options_json.h rebuilds its options).
struct RecordedOptions {
  std::string matcher_json = "{}";  // Matcher::DescribeOptionsJson()
  std::string matcher_type;         // its "type"; "" when not recorded
  MapBuilderOptions builder;
  FrameSourceOptions source;
};
// The builder's fields at the top level, "matcher" and "source" as objects.
nlohmann::json ToJson(const RecordedOptions& options);
// The record of a map built by `matcher` with `options` from `source`'s frames, as JSON text (map.json's and
// sweep.json's "options").
std::string DescribeMapOptions(const Matcher& matcher, const MapBuilderOptions& options,
                               const FrameSourceOptions& source);
// `options_json`, a record, with the threshold `tau` in place of its own (empty stays empty).
std::string RecordedAtTau(const std::string& options_json, double tau);
// Reads a record (fields it lacks keep their defaults). Throws InputError naming `where` and the key of a
// value of the wrong kind or an enum name this vmap does not know.
RecordedOptions RecordedOptionsFromJson(const std::string& options_json, const std::string& where);

// A map as ReadMap reads it, with the options it records typed: read once, for every reader of the map (vmap
// info, the report, localization, the Python module). VisualMap::options_json keeps the record as written,
// fields this vmap does not know included, to show it and to write the map again.
struct RecordedMap {
  VisualMap map;
  RecordedOptions options;
};
// Throws InputError naming map.json and the key when the map or its options cannot be read.
RecordedMap ReadRecordedMap(const std::filesystem::path& directory);

}  // namespace vmap
