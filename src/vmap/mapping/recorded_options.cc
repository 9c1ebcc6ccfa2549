#include "vmap/mapping/recorded_options.h"

#include <nlohmann/json.hpp>

#include "vmap/core/error.h"
#include "vmap/core/json_fields.h"

namespace vmap {

nlohmann::json ToJson(const RecordedOptions& options) {
  nlohmann::json record = ToJson(options.builder);
  record["matcher"] = nlohmann::json::parse(options.matcher_json);
  record["source"] = ToJson(options.source);
  return record;
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
  FromJson(fields, &options.builder);
  FromJson(fields.Object("source"), &options.source);
  const JsonFieldReader matcher = fields.Object("matcher");
  matcher.Read("type", &options.matcher_type);
  options.matcher_json = matcher.object().dump();
  return options;
}

}  // namespace vmap
