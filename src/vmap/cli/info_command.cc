// vmap info MAP_DIR: the summary of a map, from its files.

#include <iostream>

#include <nlohmann/json.hpp>

#include "vmap/cli/commands.h"
#include "vmap/map/map_io.h"
#include "vmap/report/summary.h"

namespace vmap::cli {

void AddInfoCommand(CLI::App& app) {
  auto directory = std::make_shared<std::string>();
  CLI::App* command = app.add_subcommand("info", "Print the summary of a map (and check that it is well formed)");
  command->add_option("map", *directory, "Map directory written by `vmap build`")->required();
  command->callback([directory] {
    const VisualMap map = ReadMap(*directory);
    // ReadMap checked that the options are a JSON object; their members are read whatever their types.
    const auto options = nlohmann::json::parse(map.options_json);
    auto text = [](const nlohmann::json& object, const char* name) {
      auto it = object.find(name);
      return it != object.end() && it->is_string() ? it->get<std::string>() : std::string("?");
    };
    // A map from a newer vmap may name a mean this one does not know: its summary then uses the arithmetic one.
    const QualityMean mean =
        FindEnum(kQualityMeanNames, text(options, "quality_mean")).value_or(QualityMean::kArithmetic);
    std::cout << FormatMapSummary(map, mean);
    const auto matcher = options.find("matcher"), verifier = options.find("verifier"), tau = options.find("tau");
    if (matcher != options.end() && matcher->is_object() && verifier != options.end() && verifier->is_object()) {
      std::cout << "matcher         " << text(*matcher, "type") << ", verifier " << text(*verifier, "method")
                << ", tau " << (tau != options.end() && tau->is_number() ? tau->get<double>() : 0.0) << ", similarity "
                << text(options, "similarity") << "\n";
    }
  });
}

}  // namespace vmap::cli
