// vmap info MAP_DIR: the summary of a map, from its files.

#include <iostream>

#include <nlohmann/json.hpp>

#include "vmap/cli/commands.h"
#include "vmap/mapping/map_io.h"
#include "vmap/report/summary.h"

namespace vmap::cli {

void AddInfoCommand(CLI::App& app) {
  auto directory = std::make_shared<std::string>();
  CLI::App* command = app.add_subcommand("info", "Print the summary of a map (and check that it is well formed)");
  command->add_option("map", *directory, "Map directory written by `vmap build`")->required();
  command->callback([directory] {
    const VisualMap map = ReadMap(*directory);
    const auto options = nlohmann::json::parse(map.options_json);
    const QualityMean mean = ParseQualityMean(options.value("quality_mean", std::string("arithmetic")));
    std::cout << FormatMapSummary(map, mean);
    if (options.contains("matcher") && options.contains("verifier")) {
      std::cout << "matcher         " << options["matcher"].value("type", "?") << ", verifier "
                << options["verifier"].value("method", "?") << ", tau " << options.value("tau", 0.0) << ", similarity "
                << options.value("similarity", "?") << "\n";
    }
  });
}

}  // namespace vmap::cli
