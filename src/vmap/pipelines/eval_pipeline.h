#pragma once
// The evaluation pipeline: every link of a map against ground-truth camera poses (`vmap eval MAP`), recorded
// as the map's eval.json.

#include <string>

#include "vmap/core/option_fields.h"
#include "vmap/evaluation/evaluation_inputs.h"
#include "vmap/evaluation/evaluation_json.h"
#include "vmap/evaluation/ground_truth.h"
#include "vmap/evaluation/map_evaluation.h"

namespace vmap {

// The --help section of the ground truth's flags (GroundTruthOptions, and `vmap sweep --gt`, bound by hand).
inline constexpr char kGroundTruthSection[] = "Ground truth";

// Which ground truth: a poses file, or the input's own (KITTI poses.txt, TUM groundtruth.txt, EuRoC's).
struct GroundTruthOptions {
  std::string path;  // "" = the input's own
  GroundTruthFormat format = GroundTruthFormat::kAuto;

  void VisitFields(OptionFieldVisitor& visitor);
};

struct EvalPipelineOptions {
  std::string map;  // the map directory
  GroundTruthOptions gt;
  // Intrinsics when the map has none: "fx,fy,cx,cy[,k1,k2,p1,p2[,k3[,k4,k5,k6]]]" or a calibration file.
  std::string camera;
  std::string json;  // also write the evaluation here; "" = no
  bool save = true;  // write eval.json into the map
  EvaluationOptions evaluation;

  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

struct EvalPipelineResult {
  MapEvaluation evaluation;
  std::string saved_to;  // the map's eval.json when written, else ""
};

// Stages, in order:
//   1. check the options, the outputs (none may overwrite the map, the ground truth or the camera file) and the
//      camera option;
//   2. read the map;
//   3. read the ground truth and choose the camera;
//   4. evaluate every link (a ground truth that covers none of them is refused: it would replace eval.json with
//      an evaluation of nothing);
//   5. write eval.json and the --json copy.
EvalPipelineResult RunEvalPipeline(const EvalPipelineOptions& options);

}  // namespace vmap
