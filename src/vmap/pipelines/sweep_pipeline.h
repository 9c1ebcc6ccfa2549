#pragma once
// The sweep pipeline: the paper's threshold table, one map per τ in one pass over a teach run (`vmap sweep INPUT
// --thresholds 0.1:0.9:0.1`), optionally each map written and evaluated against ground truth.

#include <string>

#include "vmap/core/option_fields.h"
#include "vmap/features/matcher_registry.h"
#include "vmap/mapping/batch_build.h"
#include "vmap/mapping/map_builder_options.h"
#include "vmap/pipelines/eval_pipeline.h"
#include "vmap/sources/frame_source.h"

namespace vmap {

struct SweepPipelineOptions {
  std::string input;
  std::string thresholds = "0.1:0.9:0.1";  // start:stop:step or a list a,b,c (ParseThresholds)
  std::string output;                      // sweep.md, sweep.csv and sweep.json (and the maps); "" = printed only
  bool write_maps = false;                 // also write each τ's map into `output`
  std::string report;                      // the sweep's HTML report: the `output` folder or one of its own
  FrameSourceOptions source;
  MatcherOptions matcher;
  MapBuilderOptions map;  // key_images.tau is each threshold's (the record gives the matcher's)
  // A usable-links column (`vmap eval`'s criterion) against `gt`: the input's own ground truth when gt.path is "".
  bool evaluate = false;
  GroundTruthOptions gt;

  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
  // `map` with the matcher's τ, the one its record gives (each map's τ is its threshold's).
  MapBuilderOptions ResolvedMapOptions() const;
};

// Stages, in order:
//   1. check the options, parse the thresholds;
//   2. claim the output folders (refused before any work when they are not vmap's or hold the input);
//   3. create the matcher and open the input;
//   4. read the ground truth (a missing file fails now, not after the whole input);
//   5. sweep every τ in one pass (SweepThresholds);
//   6. evaluate each τ's map;
//   7. write each map's evaluation and report, the sweep's files and report, and commit.
SweepResult RunSweepPipeline(const SweepPipelineOptions& options);

}  // namespace vmap
