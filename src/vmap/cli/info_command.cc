// vmap info MAP_DIR: the summary of a map, from its files.

#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "vmap/cli/commands.h"
#include "vmap/map/map_io.h"
#include "vmap/mapping/recorded_options.h"
#include "vmap/report/summary.h"
#include "vmap/sources/recording_reader.h"
#include "vmap/sources/recording_source.h"

namespace vmap::cli {

void AddInfoCommand(CLI::App& app) {
  auto directory = std::make_shared<std::string>();
  CLI::App* command = app.add_subcommand(
      "info", "Print the summary of a map (and check that it is well formed), or the topics of a recording");
  command
      ->add_option("map", *directory,
                   "Map directory written by `vmap build`, or a recording (ROS bag, rosbag2 "
                   "folder, MCAP file): its topics with type, count, rate and image size")
      ->required();
  command->callback([directory] {
    if (IsRecording(*directory)) {
      std::cout << FormatRecordingTopics(*directory, DescribeRecording(*directory));
      return;
    }
    const RecordedMap read = ReadRecordedMap(*directory);
    const VisualMap& map = read.map;
    const RecordedOptions& options = read.options;
    std::cout << FormatMapSummary(map, options.builder.quality_mean);
    if (!map.experiences.empty()) {
      std::vector<std::string> views;
      for (const Experience& experience : map.experiences) views.push_back(std::to_string(experience.views.size()));
      std::cout << fmt::format("experiences     {} ({} views of the {} key images)\n", map.experiences.size(),
                               fmt::join(views, ", "), map.key_images.size());
    }
    if (!options.matcher_type.empty()) {
      std::cout << "matcher         " << options.matcher_type << ", verifier "
                << VerifierMethodName(options.builder.verifier.method) << ", tau " << options.builder.key_images.tau
                << ", similarity " << SimilarityModeName(options.builder.key_images.similarity) << "\n";
    }
  });
}

}  // namespace vmap::cli
