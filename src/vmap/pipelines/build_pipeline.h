#pragma once
// The build pipeline: a teach run in, a map directory out. What `vmap build INPUT -o MAP`, vmap.build_map and
// the ROS node's teach run all run: resolve the options, claim the output folder, create the matcher, open the
// input, build (frame by frame, with snapshots while it runs, or by bisection), write the report, commit.

#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "vmap/core/option_fields.h"
#include "vmap/features/matcher_registry.h"
#include "vmap/map/visual_map.h"
#include "vmap/mapping/map_builder_options.h"
#include "vmap/sources/frame_source.h"

namespace vmap {

struct BuildPipelineOptions {
  std::string input;   // the teach run: a video, an image folder, a dataset, a recording or a live input
  std::string output;  // the map directory; "" = "<input name>_map" in the working directory
  FrameSourceOptions source;
  MatcherOptions matcher;
  // Algorithm 1's threshold in (0, 1]; unset = the matcher's (DefaultTau). It replaces map.key_images.tau, whose
  // default knows no matcher.
  std::optional<double> tau;
  MapBuilderOptions map;
  bool report = false;          // also write report.html into the map
  double snapshot_every = 0.0;  // seconds between snapshots of the map so far, written while the run goes on; 0 = none
  // The input ends when the host says so (InputEndRequested, core/interrupt.h: the CLI's first SIGINT), and the map
  // is finished from the frames seen: for cameras and streams. The host turns that on (EndInputOnSigint).
  bool until_interrupted = false;
  // The host's own files, written into the map folder before each snapshot and the map itself are committed, so
  // that a run killed between snapshots keeps them with the map they belong to (the ROS teach run's odometry). Not
  // an option: no flag or JSON field. Throws as a file of the map that cannot be written does.
  std::function<void(const std::filesystem::path& map_folder)> write_beside_map;
  // The names of the files write_beside_map writes: this run's own, so that a map it replaces keeps none of them (an
  // earlier teach run's odometry is not this run's, even where this run wrote none). A rebuild keeps the others.
  std::vector<std::string> files_beside_map;

  // The fields above, each once: the positional input, -o, the input's, the matchers', τ, the builder's and the
  // verifier's options, --report, --snapshot-every, --until-interrupted. Every field's path is the one its check
  // names ("first", "key_images.similarity", "verifier.threshold", "orb.num_features").
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field

  // `map` with τ resolved (the matcher's when `tau` is unset).
  MapBuilderOptions ResolvedMapOptions() const;
  // `output`, or the default next to the working directory.
  std::filesystem::path OutputDirectory() const;
  // What the build reads, which its output may not replace: the input, and the camera and camera mask files when
  // it is given them.
  std::vector<std::string> FilesRead() const;
};

struct BuildPipelineResult {
  VisualMap map;
  std::filesystem::path directory;  // where the map was committed
  bool interrupted = false;         // until_interrupted: the input was ended by the host
};

// Runs the pipeline on `options.input`, or on `source` when one is given (a host's own frames, e.g. a ROS topic;
// `options.input` is then only recorded). Stages, in order:
//   1. check the options and resolve τ;
//   2. claim the output folder (a folder that is not vmap's or holds the input is refused before any work);
//   3. create the matcher;
//   4. open the input;
//   5. build the map: frame by frame through a MapBuilder (snapshots, the host's end of input, the builder's
//      after_frame hook), or by bisection (key_search bisect);
//   6. write the report when asked, and the host's files (write_beside_map);
//   7. commit the folder.
// Throws InputError (OptionError for an option) and leaves the output as it was on any failure. `source_files`: with
// `source`, the files its frames come from (a simulator's route and textures), which the output may not replace.
BuildPipelineResult RunBuildPipeline(const BuildPipelineOptions& options, FrameSource* source = nullptr,
                                     const std::vector<std::string>& source_files = {});

}  // namespace vmap
