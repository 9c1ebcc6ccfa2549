#include "vmap/mapping/recorded_options.h"

#include <nlohmann/json.hpp>

#include "vmap/core/error.h"
#include "vmap/core/options_json.h"
#include "vmap/map/map_io.h"

namespace vmap {

nlohmann::json ToJson(const RecordedOptions& options) {
  MapBuilderOptions builder = options.builder;
  builder.key_search = ResolveKeySearch(builder);  // the search that ran
  nlohmann::json record = OptionsToJson(builder);
  record["matcher"] = nlohmann::json::parse(options.matcher_json);
  record["source"] = OptionsToJson(options.source);
  return record;
}

std::string DescribeMapOptions(const Matcher& matcher, const MapBuilderOptions& options,
                               const FrameSourceOptions& source) {
  RecordedOptions record;
  record.matcher_json = matcher.DescribeOptionsJson();
  record.builder = options;
  record.source = source;
  return ToJson(record).dump();
}

RecordedOptions RecordedOptionsFromJson(const std::string& options_json, const std::string& where) {
  nlohmann::json record;
  try {
    record = nlohmann::json::parse(options_json);
  } catch (const nlohmann::json::exception&) {
    throw InputError(where + " is not valid JSON");
  }
  const JsonFieldReader fields(record, where);
  RecordedOptions options;
  OptionsFromJson(fields, &options.builder);
  OptionsFromJson(fields.Object("source"), &options.source);
  const JsonFieldReader matcher = fields.Object("matcher");
  matcher.Read("type", &options.matcher_type);
  options.matcher_json = matcher.object().dump();
  return options;
}

RecordedMap ReadRecordedMap(const std::filesystem::path& directory) {
  RecordedMap read;
  read.map = ReadMap(directory);
  read.options =
      RecordedOptionsFromJson(read.map.options_json, "map '" + (directory / kMapFileName).string() + "': options");
  return read;
}

}  // namespace vmap
