#include "vmap/mapping/recorded_options.h"

#include <algorithm>
#include <string>

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

std::string RecordedAtTau(const std::string& options_json, double tau) {
  if (options_json.empty()) return options_json;
  nlohmann::json record = nlohmann::json::parse(options_json);
  record["tau"] = tau;  // key_images.tau, written at the top (ToJson)
  return record.dump();
}

namespace {

// The key of the record that holds the field at `path` of an options struct: the record writes some nested structs'
// fields at the top ("tau" for key_images.tau), so the path's shortest ending that the record has.
std::string RecordKey(const nlohmann::json& record, const std::string& path) {
  for (size_t from = 0; from < path.size();) {
    const nlohmann::json* value = &record;
    for (size_t at = from; value != nullptr && at <= path.size();) {
      const size_t dot = std::min(path.find('.', at), path.size());
      const std::string key = path.substr(at, dot - at);
      value = value->is_object() && value->contains(key) ? &(*value)[key] : nullptr;
      at = dot + 1;
    }
    if (value != nullptr) return path.substr(from);
    const size_t dot = path.find('.', from);
    if (dot == std::string::npos) break;
    from = dot + 1;
  }
  return path;
}

}  // namespace

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
  // A value no build takes (a hand edit) is the map's error, named by its key here, not later an option's error of
  // the command reading the map ("map_tau 7 is outside [0, 1]" from localize, whose map_tau the user never gave).
  const auto check = [&](const auto& recorded, const nlohmann::json& in, const std::string& at) {
    try {
      recorded.Check();
    } catch (const OptionError& error) {
      throw InputError(where + "." + at + RecordKey(in, error.path()) + " " + error.problem() +
                       "; rebuild the map with `vmap build`");
    }
  };
  check(options.builder, record, "");
  check(options.source, record.value("source", nlohmann::json::object()), "source.");
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
