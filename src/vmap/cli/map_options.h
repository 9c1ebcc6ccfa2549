#pragma once
// Options of key-image selection and the record of every option in map.json.

#include <filesystem>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "vmap/cli/option_flags.h"
#include "vmap/core/atomic_output.h"
#include "vmap/features/matcher.h"
#include "vmap/mapping/batch_build.h"

namespace vmap::cli {

// --tau, --similarity, --quality, --no-final-key, --threads, --exhaustive, --search, --search-window: bound
// straight onto `options` (the library's defaults), but for tau, whose default depends on the matcher.
struct KeyImageFlags {
  MapBuilderOptions options;
  std::optional<double> tau;  // --tau; unset: the matcher's DefaultTau
  // `options` with tau (`matcher_type` gives it when --tau was not given), key images and links checked.
  MapBuilderOptions Resolve(const std::string& matcher_type) const;
};
// Also --min-key-displacement, --pose, --pose-threshold, --pose-matches, --exhaustive, --search, --search-window;
// fields as MapBuilderOptions names them.
void AddKeyImageOptions(CLI::App* command, KeyImageFlags& flags, OptionFlags& option_flags, bool with_tau = true);

// Every option that shaped a map, as JSON text for map.json.
std::string DescribeOptions(const Matcher& matcher, const MapBuilderOptions& options, const FrameSourceOptions& source);

// Writes report.html into a map directory when asked (and when this vmap has the report stage).
void WriteReportIfAsked(bool asked, const std::filesystem::path& map_directory);

// What `-o` may replace: an empty folder or a map (a sweep) that vmap wrote, never one that is, holds or lies
// inside the input.
OutputPolicy MapOutputPolicy(const std::string& input);
OutputPolicy SweepOutputPolicy(const std::string& input);

// Writes sweep.md, sweep.csv and sweep.json into `directory`.
void WriteSweepFiles(const SweepResult& sweep, const std::filesystem::path& directory);

}  // namespace vmap::cli
