#include "vmap/pipelines/eval_pipeline.h"

#include <algorithm>
#include <filesystem>
#include <optional>
#include <vector>

#include <spdlog/spdlog.h>

#include "vmap/core/atomic_output.h"
#include "vmap/core/error.h"
#include "vmap/map/map_io.h"
#include "vmap/pipelines/output_policies.h"

namespace vmap {
namespace fs = std::filesystem;

void GroundTruthOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Section(kGroundTruthSection);
  visitor.Visit(OptionField{"path", "--gt",
                            "Ground-truth poses (default: the input's own: KITTI poses.txt, TUM groundtruth.txt, EuRoC "
                            "state_groundtruth_estimate0/data.csv). Formats: kitti, tum, euroc"}
                    .HideDefault(),
                path);
  visitor.Visit(OptionField{"format", "--gt-format", "Format of --gt (auto: from its first line): "}.ListingNames(),
                EnumField(format, kGroundTruthFormatNames, ParseGroundTruthFormat));
}

void EvalPipelineOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit(OptionField{"map", "map", "Map directory written by `vmap build`"}.Positional(), map);
  visitor.VisitNested("gt", gt);
  visitor.Visit(OptionField{"camera", "--camera",
                            "Intrinsics when the map has none: fx,fy,cx,cy[,k1,k2,p1,p2[,k3[,k4,k5,k6]]] or a "
                            "calibration file"}
                    .HideDefault(),
                camera);
  visitor.Visit(
      OptionField{"json", "--json", "Also write the evaluation (JSON) to this file"}.HideDefault().NotRecorded(), json);
  visitor.Visit(OptionField{"save", "!--no-save", "Do not write eval.json into the map directory"}.NotRecorded(), save);
  visitor.VisitNested("", evaluation);
}

void EvalPipelineOptions::Check() const {
  evaluation.Check();
  // The input's own ground truth is read in the input's own format: a format without --gt would be ignored.
  if (gt.path.empty() && gt.format != GroundTruthFormat::kAuto) {
    throw OptionError("gt.format",
                      "needs path, the ground-truth file it describes (the input's own is read in its own "
                      "format)",
                      {"path"});
  }
}

namespace {

// Below this mean share of verified matches within the threshold of the true epipolar lines, the ground truth is not
// plausibly the map's: ORB maps against their own ground truth give 0.80-1.0 (docs/measurements/links.md), ground truth
// of another run or shifted by half a second 0.03-0.07. Low enough for matchers less precise than ORB.
constexpr double kLeastPlausibleVerifiedWithin = 0.25;

// Why ground truth gives no key image of `map` a pose, as far as the map tells.
std::string WhyNoKeyImageHasAPose(const VisualMap& map, const GroundTruth& truth) {
  const std::string fix = "give the ground truth of the map's input '" + map.input.path + "'";
  if (truth.format == GroundTruthFormat::kKitti) {
    return fix + (truth.lines_by_file_number ? " (KITTI poses are matched by the number in each image's file name)"
                                             : " (KITTI poses are matched by each key image's position in the input)");
  }
  const bool timed =
      std::any_of(map.key_images.begin(), map.key_images.end(), [](const KeyImage& key) { return key.timestamp >= 0; });
  if (!timed) {
    return "the map's key images have no timestamps (its input gives none), and " +
           GroundTruthFormatName(truth.format) +
           " ground truth is matched by time: give KITTI-format poses (one line per frame), or rebuild the map from "
           "an input with timestamps";
  }
  return fix + " and check that its timestamps are the key images' (seconds, the same clock)";
}

}  // namespace

EvalPipelineResult RunEvalPipeline(const EvalPipelineOptions& options) {
  // 1. The options, the outputs, the camera option.
  options.Check();
  // `--json MAP/eval.json` names the file eval keeps in the map: it is written once, as the map's.
  std::string json_output = options.json;
  if (!json_output.empty() && SameOutput(json_output, fs::path(options.map) / kEvaluationFileName)) {
    if (!options.save) {
      throw OptionError("json",
                        "'" + options.json + "' is the map's own evaluation, and save asks to leave that as it is: " +
                            "drop one of the two",
                        {"save"});
    }
    json_output.clear();
  }
  CheckOutputs({{json_output, "json"}},
               {MapInputs(options.map), NamedInput(options.gt.path, "the ground truth"),
                fs::is_regular_file(options.camera) ? NamedInput(options.camera, "the camera file")
                                                    : std::vector<OutputInput>{}});
  ParseEvaluationCamera(options.camera);  // a wrong camera is refused first, even where the map's camera is used

  // 2. The map.
  const VisualMap map = ReadMap(options.map);

  // 3. The ground truth and the camera.
  const GroundTruth truth = MapGroundTruth(map, options.gt.path, options.gt.format);
  const Camera camera = EvaluationCamera(map, options.camera);

  // 4. Every link.
  EvalPipelineResult result;
  MapEvaluation& evaluation = result.evaluation;
  evaluation = EvaluateMap(map, truth, camera, options.evaluation);
  evaluation.map_path = options.map;
  if (evaluation.summary.links > 0 && evaluation.summary.evaluated_links == 0) {
    // Ground truth of another sequence: an evaluation of nothing would replace eval.json all the same.
    throw InputError("the ground truth '" + truth.path + "' (read as " + GroundTruthFormatName(truth.format) +
                     ") covers none of the map's " + std::to_string(evaluation.summary.links) +
                     " links (no pose for both key images of any); " + WhyNoKeyImageHasAPose(map, truth));
  }
  if (evaluation.summary.evaluated_links < evaluation.summary.links) {
    spdlog::warn("the ground truth covers {} of the map's {} links; the others are left out",
                 evaluation.summary.evaluated_links, evaluation.summary.links);
  }
  // Ground truth of another sequence, shifted in time or numbered from another frame still gives poses, but the
  // matches do not lie on its epipolar lines, where a map's verified matches do (kLeastPlausibleVerifiedWithin).
  if (evaluation.summary.verified_within_mean < kLeastPlausibleVerifiedWithin) {
    spdlog::warn(
        "only {:.0f} % of the verified matches lie within {:g} px of the ground truth's epipolar lines (an ORB map's "
        "against its own: 80-100 %): is '{}' the ground truth of the map's input, at the same times and frame "
        "numbers, and is the camera right? The figures below judge the map against it as given",
        100.0 * evaluation.summary.verified_within_mean, evaluation.options.sampson_threshold_px, truth.path);
  }

  // 5. The records: both written before either is put in place, so that a failure while writing one (a full disk)
  // leaves both as they were.
  const std::string json = EvaluationToJson(evaluation);
  std::optional<PendingFile> saved;
  if (options.save) {
    result.saved_to = (fs::path(options.map) / kEvaluationFileName).string();
    saved.emplace(result.saved_to, json);
  }
  std::optional<PendingFile> json_file;
  if (!json_output.empty()) json_file.emplace(json_output, json);
  if (saved) saved->Commit();
  if (json_file) json_file->Commit();
  return result;
}

}  // namespace vmap
