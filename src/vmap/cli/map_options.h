#pragma once
// Options of key-image selection and the record of every option in map.json.

#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>

#include "vmap/features/matcher.h"
#include "vmap/mapping/map_builder.h"

namespace vmap::cli {

// --tau, --similarity, --quality, --no-final-key, --threads, --exhaustive, --search, --search-window.
struct KeyImageFlags {
  double tau = 0.5;
  std::string similarity = "inlier-ratio";
  std::string quality = "arithmetic";
  bool final_key = true;
  int threads = 0;
  bool exhaustive = false;
  std::string search = "auto";
  int search_window = 32;
  MapBuilderOptions Resolve() const;
};
void AddKeyImageOptions(CLI::App* command, KeyImageFlags& flags, bool with_tau = true);

// Every option that shaped a map, as JSON text for map.json.
std::string DescribeOptions(const Matcher& matcher, const MapBuilderOptions& options,
                            const FrameSourceOptions& source);

// Writes report.html into a map directory when asked (and when this vmap has the report stage).
void WriteReportIfAsked(bool asked, const std::filesystem::path& map_directory);
// Writes a sweep's report.html into `report_directory` when it is not empty; the per-tau maps in
// `sweep_directory` (if written) are linked from it.
void WriteSweepReportIfAsked(const std::string& report_directory, const SweepResult& sweep,
                             const std::string& sweep_directory);

}  // namespace vmap::cli
