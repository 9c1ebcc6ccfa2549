#pragma once
// Options of key-image selection and the record of every option in map.json.

#include <filesystem>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "vmap/cli/option_flags.h"
#include "vmap/core/atomic_output.h"
#include "vmap/features/matcher.h"
#include "vmap/mapping/map_builder.h"

namespace vmap::cli {

// --tau, --similarity, --quality, --no-final-key, --threads, --exhaustive, --search, --search-window.
struct KeyImageFlags {
  std::optional<double> tau;  // --tau; unset: the matcher's DefaultTau
  std::string similarity = "inlier-ratio";
  std::string quality = "arithmetic";
  bool final_key = true;
  int threads = 0;
  double min_key_displacement = KeyImageOptions().min_key_displacement;
  // The pose of each link (with a camera) and the homography test.
  std::string pose_method = PoseMethodName(PoseOptions().method);
  double pose_threshold = PoseOptions().threshold;
  std::string pose_matches = PoseOptions().use_all_matches ? "all" : "verified";
  bool exhaustive = false;
  std::string search = "auto";
  int search_window = 32;
  // `matcher_type` gives tau when --tau was not given.
  MapBuilderOptions Resolve(const std::string& matcher_type) const;
};
// Also --min-key-displacement, --pose, --pose-threshold, --pose-matches, --exhaustive, --search, --search-window;
// fields as MapBuilderOptions names them.
void AddKeyImageOptions(CLI::App* command, KeyImageFlags& flags, OptionFlags& option_flags, bool with_tau = true);

// Every option that shaped a map, as JSON text for map.json.
std::string DescribeOptions(const Matcher& matcher, const MapBuilderOptions& options,
                            const FrameSourceOptions& source);

// Writes report.html into a map directory when asked (and when this vmap has the report stage).
void WriteReportIfAsked(bool asked, const std::filesystem::path& map_directory);

// What `-o` may replace: an empty folder or a map (a sweep) that vmap wrote, never one that is, holds or lies
// inside the input.
OutputPolicy MapOutputPolicy(const std::string& input);
OutputPolicy SweepOutputPolicy(const std::string& input);

// Writes sweep.md, sweep.csv and sweep.json into `directory`.
void WriteSweepFiles(const SweepResult& sweep, const std::filesystem::path& directory);

}  // namespace vmap::cli
