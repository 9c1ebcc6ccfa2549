#include "vmap/evaluation/map_evaluation.h"

#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/core/file_name_encoding.h"
#include "vmap/core/numeric.h"
#include "vmap/core/options_json.h"
#include "vmap/geometry/relative_pose.h"
#include "vmap/geometry/sampson_error.h"
#include "vmap/map/map_geometry_json.h"
#include "vmap/sources/dataset_camera.h"

namespace vmap {
namespace fs = std::filesystem;
using nlohmann::json;

void EvaluationOptions::Check() const {
  if (!(max_rotation_error_deg > 0 && max_rotation_error_deg <= 180)) {
    throw OptionError("max_rotation_error_deg",
                      fmt::format("{} deg is outside (0, 180]; the default is 5", max_rotation_error_deg));
  }
  if (!(max_translation_error_deg > 0 && max_translation_error_deg <= 180)) {
    throw OptionError("max_translation_error_deg",
                      fmt::format("{} deg is outside (0, 180]; the default is 20", max_translation_error_deg));
  }
  if (!(min_parallax_px >= 0 && std::isfinite(min_parallax_px))) {
    throw OptionError("min_parallax_px", fmt::format("{} px must be >= 0; the default is 10", min_parallax_px));
  }
  if (!(sampson_threshold_px > 0 && std::isfinite(sampson_threshold_px))) {
    throw OptionError("sampson_threshold_px", fmt::format("{} px must be > 0; the default is 2", sampson_threshold_px));
  }
  if (!(max_time_difference >= 0 && std::isfinite(max_time_difference))) {
    throw OptionError("max_time_difference",
                      fmt::format("{} s must be >= 0; the default is 0.02", max_time_difference));
  }
}

namespace {

// Sampson errors of matches under F, on pinhole pixels (distortion removed).
std::vector<double> SampsonErrors(const cv::Matx33d& F, const std::vector<cv::Point2d>& from,
                                  const std::vector<cv::Point2d>& to) {
  std::vector<double> errors;
  for (size_t i = 0; i < from.size(); ++i) errors.push_back(SampsonDistance(F, from[i], to[i]));
  return errors;
}

LinkEvaluation EvaluateLink(const VisualMap& map, int index, const GroundTruth& truth, const Camera& camera,
                            const EvaluationOptions& options) {
  const Link& link = map.links[index];
  const KeyImage& from = map.key_images[link.from_key];
  const KeyImage& to = map.key_images[link.to_key];
  LinkEvaluation e;
  e.link = index;
  e.from_frame = from.frame_index;
  e.to_frame = to.frame_index;
  e.from_source = from.source_index;
  e.to_source = to.source_index;
  e.below_tau = link.below_tau;
  e.planar = link.planar;
  e.similarity = link.similarity;
  e.num_verified = link.has_fundamental ? link.num_verified : 0;
  e.num_rejected = static_cast<int>(link.correspondences.size()) - e.num_verified;

  std::vector<cv::Point2f> verified_from, verified_to, rejected_from, rejected_to;
  for (size_t i = 0; i < link.correspondences.size(); ++i) {
    const bool verified = static_cast<int>(i) < e.num_verified;
    (verified ? verified_from : rejected_from).push_back(link.correspondences[i].p0);
    (verified ? verified_to : rejected_to).push_back(link.correspondences[i].p1);
  }

  // The pose to judge: the map's own, or the one its F gives.
  bool has_estimate = false;
  cv::Matx33d R_estimate;
  cv::Vec3d t_estimate;
  if (link.has_pose) {
    has_estimate = true;
    R_estimate = link.R;
    t_estimate = link.t;
    e.pose_source = "stored";
  } else if (link.has_fundamental && e.num_verified >= 5) {
    const RelativePose pose = PoseFromFundamental(link.F, camera, verified_from, verified_to);
    if (pose.valid) {
      has_estimate = true;
      R_estimate = pose.R;
      t_estimate = pose.t;
      e.pose_source = "fundamental";
    }
  }
  if (!has_estimate) e.pose_source = "none";
  e.translation_known = link.has_pose && link.translation_known;
  if (link.has_pose && link.translation_sigma_deg >= 0) e.translation_sigma_deg = link.translation_sigma_deg;

  const std::optional<cv::Matx44d> T_from = KeyImagePose(truth, from, options.max_time_difference);
  const std::optional<cv::Matx44d> T_to = KeyImagePose(truth, to, options.max_time_difference);
  if (!T_from || !T_to) return e;
  e.has_ground_truth = true;
  cv::Matx33d R_true;
  cv::Vec3d t_true;
  RelativeFromCameraToWorld(*T_from, *T_to, &R_true, &t_true);
  e.true_rotation_deg = RotationAngleDeg(R_true);
  e.true_baseline = cv::norm(t_true);

  if (e.true_baseline > 1e-9) {
    const cv::Matx33d F_true = FundamentalFromPose(R_true, t_true, camera.K());
    const std::vector<double> verified_errors =
        SampsonErrors(F_true, UndistortPixels(camera, verified_from), UndistortPixels(camera, verified_to));
    const std::vector<double> rejected_errors =
        SampsonErrors(F_true, UndistortPixels(camera, rejected_from), UndistortPixels(camera, rejected_to));
    e.verified_sampson_median = MedianOrNan(verified_errors);
    e.verified_within = ShareBelow(verified_errors, options.sampson_threshold_px);
    e.rejected_sampson_median = MedianOrNan(rejected_errors);
    e.rejected_within = ShareBelow(rejected_errors, options.sampson_threshold_px);
    std::vector<cv::Point2f> consistent_from, consistent_to;
    for (size_t i = 0; i < verified_errors.size(); ++i) {
      if (verified_errors[i] >= options.sampson_threshold_px) continue;
      consistent_from.push_back(verified_from[i]);
      consistent_to.push_back(verified_to[i]);
    }
    for (size_t i = 0; i < rejected_errors.size(); ++i) {
      if (rejected_errors[i] >= options.sampson_threshold_px) continue;
      consistent_from.push_back(rejected_from[i]);
      consistent_to.push_back(rejected_to[i]);
    }
    e.consistent_matches = static_cast<int>(consistent_from.size());
    if (!consistent_from.empty()) {
      e.true_parallax_px = Median(Displacements(consistent_from, consistent_to, &camera, &R_true));
    }
  } else if (!link.correspondences.empty()) {
    // No baseline: every match agrees with a pure rotation and none has parallax to speak of.
    std::vector<cv::Point2f> all_from = verified_from, all_to = verified_to;
    all_from.insert(all_from.end(), rejected_from.begin(), rejected_from.end());
    all_to.insert(all_to.end(), rejected_to.begin(), rejected_to.end());
    e.true_parallax_px = Median(Displacements(all_from, all_to, &camera, &R_true));
  }
  if (has_estimate) {
    if (e.true_baseline > 1e-9) {
      std::vector<cv::Point2f> all_from = verified_from, all_to = verified_to;
      all_from.insert(all_from.end(), rejected_from.begin(), rejected_from.end());
      all_to.insert(all_to.end(), rejected_to.begin(), rejected_to.end());
      RelativePose estimate, truth_pose;
      estimate.valid = truth_pose.valid = true;
      estimate.R = R_estimate;
      estimate.t = t_estimate;
      truth_pose.R = R_true;
      truth_pose.t = cv::normalize(t_true);
      e.true_pose_cost_excess = PoseCost(truth_pose, camera, all_from, all_to, PoseOptions()) -
                                PoseCost(estimate, camera, all_from, all_to, PoseOptions());
    }
    e.rotation_error_deg = RotationAngleDeg(R_estimate.t() * R_true);
    if (e.true_baseline > 1e-9) e.translation_error_deg = AngleBetweenDeg(t_estimate, t_true);
    const bool translation_judged = std::isfinite(e.true_parallax_px) && e.true_parallax_px >= options.min_parallax_px;
    const bool rotation_right = e.rotation_error_deg < options.max_rotation_error_deg;
    const bool translation_right =
        std::isfinite(e.translation_error_deg) && e.translation_error_deg < options.max_translation_error_deg;
    e.usable = rotation_right && (!translation_judged || translation_right);
    e.strict_usable = rotation_right && translation_right;
  }
  return e;
}

json Number(double value) { return std::isfinite(value) ? json(value) : json(nullptr); }

double NumberField(const json& object, const char* name) {
  const auto it = object.find(name);
  if (it == object.end() || !it->is_number()) return NAN;
  return it->get<double>();
}

}  // namespace

MapEvaluation EvaluateMap(const VisualMap& map, const GroundTruth& truth, const Camera& camera,
                          const EvaluationOptions& options) {
  options.Check();
  MapEvaluation evaluation;
  evaluation.ground_truth_path = truth.path;
  evaluation.ground_truth_format = truth.format;
  evaluation.camera = camera;
  evaluation.options = options;
  std::vector<double> rotation_errors, translation_errors, verified_within, rejected_within, cost_excesses;
  EvaluationSummary& s = evaluation.summary;
  for (int i = 0; i < static_cast<int>(map.links.size()); ++i) {
    LinkEvaluation e = EvaluateLink(map, i, truth, camera, options);
    ++s.links;
    if (e.pose_source != "none") ++s.links_with_pose;
    if (e.has_ground_truth) {
      ++s.evaluated_links;
      s.usable_links += e.usable ? 1 : 0;
      rotation_errors.push_back(e.rotation_error_deg);
      cost_excesses.push_back(e.true_pose_cost_excess);
      if (std::isfinite(e.true_parallax_px) && e.true_parallax_px >= options.min_parallax_px) {
        translation_errors.push_back(e.translation_error_deg);
      }
      verified_within.push_back(e.verified_within);
      rejected_within.push_back(e.rejected_within);
      s.strict_usable_links += e.strict_usable ? 1 : 0;
      if (e.translation_known) {
        ++s.unflagged_links;
        s.unflagged_right_links += e.strict_usable ? 1 : 0;
        s.unflagged_usable_links += e.usable ? 1 : 0;
        s.unflagged_reversed_links += std::isfinite(e.translation_error_deg) && e.translation_error_deg > 90 ? 1 : 0;
      } else {
        ++s.flagged_links;
        s.flagged_wrong_links += e.strict_usable ? 0 : 1;
      }
    }
    evaluation.links.push_back(std::move(e));
  }
  const auto share = [](int part, int whole) { return whole > 0 ? static_cast<double>(part) / whole : NAN; };
  s.usable_share = share(s.usable_links, s.evaluated_links);
  s.strict_usable_share = share(s.strict_usable_links, s.evaluated_links);
  s.flagged_wrong_share = share(s.flagged_wrong_links, s.flagged_links);
  s.unflagged_right_share = share(s.unflagged_right_links, s.unflagged_links);
  s.unflagged_usable_share = share(s.unflagged_usable_links, s.unflagged_links);
  s.rotation_error_deg_median = MedianOfFinite(rotation_errors);
  s.translation_error_deg_median = MedianOfFinite(translation_errors);
  s.true_pose_cost_excess_median = MedianOfFinite(cost_excesses);
  s.verified_within_mean = MeanOfFinite(verified_within);
  s.rejected_within_mean = MeanOfFinite(rejected_within);
  return evaluation;
}

std::optional<Camera> ParseEvaluationCamera(const std::string& camera_option) {
  std::optional<Camera> camera;
  if (!camera_option.empty()) {
    // Checked even where the map's own camera is used, so that a wrong value is never silently passed over.
    std::error_code ec;
    if (fs::exists(camera_option, ec) && !fs::is_regular_file(camera_option, ec)) {
      throw OptionError("camera", "'" + camera_option +
                                      "' is not a regular file; give a calibration file or "
                                      "fx,fy,cx,cy[,k1,k2,p1,p2[,k3[,k4,k5,k6]]]");
    }
    camera = ParseCameraOption(camera_option);
    try {
      camera->Check();
    } catch (const OptionError&) {
      throw;
    } catch (const InputError& error) {
      throw OptionError("camera", "'" + camera_option + "': " + error.what());
    }
  }
  return camera;
}

Camera EvaluationCamera(const VisualMap& map, const std::string& camera_option) {
  std::optional<Camera> camera = ParseEvaluationCamera(camera_option);
  if (map.input.camera) {
    if (camera) spdlog::warn("the map records its camera, which is used; --camera is for maps that have none");
    return *map.input.camera;
  }
  if (!camera) camera = FindDatasetCamera(map.input.path, map.input.format);
  if (!camera) {
    throw OptionError("camera", "is needed: the map has no camera and its input '" + map.input.path +
                                    "' brings none; give the intrinsics fx,fy,cx,cy (or a calibration file)");
  }
  const cv::Size native = map.input.native_size.area() > 0 ? map.input.native_size : map.input.frame_size;
  const cv::Size frames = map.input.frame_size.area() > 0 ? map.input.frame_size : native;
  if (native.area() <= 0) throw InputError("the map does not record its frame size; rebuild it with `vmap build`");
  return CameraForFrames(*camera, native, frames);
}

GroundTruth MapGroundTruth(const VisualMap& map, const std::string& gt_path, GroundTruthFormat format) {
  if (!gt_path.empty()) return NameOptionErrorsWithin("gt", [&] { return ReadGroundTruth(gt_path, format); });
  std::optional<GroundTruth> truth = FindGroundTruth(map.input.path, map.input.format);
  if (!truth) {
    throw OptionError("gt.path", "is needed: the map's input '" + map.input.path +
                                     "' has no ground truth beside it (KITTI poses.txt, TUM groundtruth.txt, EuRoC "
                                     "state_groundtruth_estimate0/data.csv); give a poses file");
  }
  return *truth;
}

std::string EvaluationToJson(const MapEvaluation& evaluation) {
  json doc;
  doc["format"] = "vmap-eval";
  doc["schema_version"] = 1;
  // Paths percent-encoded where they are not UTF-8, as in map.json (file_name_encoding.h).
  doc["map"] = EncodeFileName(evaluation.map_path);
  doc["ground_truth"] = {{"path", EncodeFileName(evaluation.ground_truth_path)},
                         {"format", GroundTruthFormatName(evaluation.ground_truth_format)}};
  doc["camera"] = CameraToJson(evaluation.camera);
  doc["options"] = OptionsToJson(evaluation.options);
  json links = json::array();
  for (const LinkEvaluation& e : evaluation.links) {
    links.push_back({{"link", e.link},
                     {"from_frame", e.from_frame},
                     {"to_frame", e.to_frame},
                     {"from_source", e.from_source},
                     {"to_source", e.to_source},
                     {"below_tau", e.below_tau},
                     {"planar", e.planar},
                     {"similarity", e.similarity},
                     {"verified", e.num_verified},
                     {"rejected", e.num_rejected},
                     {"has_ground_truth", e.has_ground_truth},
                     {"pose_source", e.pose_source},
                     {"true_rotation_deg", Number(e.true_rotation_deg)},
                     {"true_baseline", Number(e.true_baseline)},
                     {"true_parallax_px", Number(e.true_parallax_px)},
                     {"consistent_matches", e.consistent_matches},
                     {"translation_known", e.translation_known},
                     {"translation_sigma_deg", Number(e.translation_sigma_deg)},
                     {"true_pose_cost_excess", Number(e.true_pose_cost_excess)},
                     {"strict_usable", e.strict_usable},
                     {"rotation_error_deg", Number(e.rotation_error_deg)},
                     {"translation_error_deg", Number(e.translation_error_deg)},
                     {"verified_sampson_median_px", Number(e.verified_sampson_median)},
                     {"verified_within_threshold", Number(e.verified_within)},
                     {"rejected_sampson_median_px", Number(e.rejected_sampson_median)},
                     {"rejected_within_threshold", Number(e.rejected_within)},
                     {"usable", e.usable}});
  }
  doc["links"] = std::move(links);
  const EvaluationSummary& s = evaluation.summary;
  doc["summary"] = {{"links", s.links},
                    {"evaluated_links", s.evaluated_links},
                    {"usable_links", s.usable_links},
                    {"usable_share", Number(s.usable_share)},
                    {"links_with_pose", s.links_with_pose},
                    {"rotation_error_deg_median", Number(s.rotation_error_deg_median)},
                    {"true_pose_cost_excess_median", Number(s.true_pose_cost_excess_median)},
                    {"translation_error_deg_median", Number(s.translation_error_deg_median)},
                    {"verified_within_threshold_mean", Number(s.verified_within_mean)},
                    {"rejected_within_threshold_mean", Number(s.rejected_within_mean)},
                    {"strict_usable_links", s.strict_usable_links},
                    {"strict_usable_share", Number(s.strict_usable_share)},
                    {"flagged_links", s.flagged_links},
                    {"flagged_wrong_links", s.flagged_wrong_links},
                    {"flagged_wrong_share", Number(s.flagged_wrong_share)},
                    {"unflagged_links", s.unflagged_links},
                    {"unflagged_right_links", s.unflagged_right_links},
                    {"unflagged_right_share", Number(s.unflagged_right_share)},
                    {"unflagged_usable_links", s.unflagged_usable_links},
                    {"unflagged_usable_share", Number(s.unflagged_usable_share)},
                    {"unflagged_reversed_links", s.unflagged_reversed_links}};
  return doc.dump(1) + "\n";
}

MapEvaluation ReadEvaluation(const std::string& path) {
  std::string why_not;
  const std::optional<ContainedFile> file = ContainedFile::OpenRegular(path, &why_not);
  if (!file) throw InputError("evaluation '" + path + "' " + why_not + "; run `vmap eval` again");
  // Some 25 values a link.
  constexpr std::uint64_t kMaxValues = 1ull << 24;
  json doc;
  why_not = file->ParseJson(kMaxValues, &doc);
  if (!why_not.empty()) throw InputError("evaluation '" + path + "' " + why_not + "; run `vmap eval` again");
  if (!doc.is_object() || doc.value("format", "") != "vmap-eval" || !doc.contains("links") ||
      !doc["links"].is_array() || !doc.contains("summary") || !doc["summary"].is_object()) {
    throw InputError("'" + path + "' is not an evaluation written by `vmap eval`; run `vmap eval` again");
  }
  MapEvaluation evaluation;
  try {
    evaluation.map_path = DecodeFileName(doc.value("map", ""));
    const json& gt = doc.contains("ground_truth") ? doc["ground_truth"] : json::object();
    evaluation.ground_truth_path = DecodeFileName(gt.value("path", ""));
    evaluation.ground_truth_format = ParseGroundTruthFormat(gt.value("format", "auto"));
    if (doc.contains("camera") && doc["camera"].is_object()) {
      evaluation.camera = CameraFromJson(doc["camera"], path, "camera");
    }
    const json& options = doc.contains("options") ? doc["options"] : json::object();
    OptionsFromJson(JsonFieldReader(options, "evaluation '" + path + "': options"), &evaluation.options);
    for (const json& l : doc["links"]) {
      LinkEvaluation e;
      e.link = l.at("link").get<int>();
      e.from_frame = l.at("from_frame").get<int>();
      e.to_frame = l.at("to_frame").get<int>();
      e.from_source = l.value("from_source", e.from_frame);
      e.to_source = l.value("to_source", e.to_frame);
      e.below_tau = l.value("below_tau", false);
      e.planar = l.value("planar", false);
      e.similarity = l.value("similarity", 0.0);
      e.num_verified = l.value("verified", 0);
      e.num_rejected = l.value("rejected", 0);
      e.has_ground_truth = l.value("has_ground_truth", false);
      e.pose_source = l.value("pose_source", "none");
      e.true_rotation_deg = NumberField(l, "true_rotation_deg");
      e.true_baseline = NumberField(l, "true_baseline");
      e.true_parallax_px = NumberField(l, "true_parallax_px");
      e.rotation_error_deg = NumberField(l, "rotation_error_deg");
      e.translation_error_deg = NumberField(l, "translation_error_deg");
      e.true_pose_cost_excess = NumberField(l, "true_pose_cost_excess");
      e.verified_sampson_median = NumberField(l, "verified_sampson_median_px");
      e.verified_within = NumberField(l, "verified_within_threshold");
      e.rejected_sampson_median = NumberField(l, "rejected_sampson_median_px");
      e.rejected_within = NumberField(l, "rejected_within_threshold");
      e.usable = l.value("usable", false);
      e.consistent_matches = l.value("consistent_matches", 0);
      e.strict_usable = l.value("strict_usable", false);
      e.translation_known = l.value("translation_known", e.pose_source == "stored");
      e.translation_sigma_deg = NumberField(l, "translation_sigma_deg");
      evaluation.links.push_back(e);
    }
    const json& s = doc["summary"];
    evaluation.summary.links = s.value("links", 0);
    evaluation.summary.evaluated_links = s.value("evaluated_links", 0);
    evaluation.summary.usable_links = s.value("usable_links", 0);
    evaluation.summary.usable_share = NumberField(s, "usable_share");
    evaluation.summary.links_with_pose = s.value("links_with_pose", 0);
    evaluation.summary.rotation_error_deg_median = NumberField(s, "rotation_error_deg_median");
    evaluation.summary.true_pose_cost_excess_median = NumberField(s, "true_pose_cost_excess_median");
    evaluation.summary.translation_error_deg_median = NumberField(s, "translation_error_deg_median");
    evaluation.summary.verified_within_mean = NumberField(s, "verified_within_threshold_mean");
    evaluation.summary.rejected_within_mean = NumberField(s, "rejected_within_threshold_mean");
    EvaluationSummary& summary = evaluation.summary;
    summary.strict_usable_links = s.value("strict_usable_links", 0);
    summary.strict_usable_share = NumberField(s, "strict_usable_share");
    summary.flagged_links = s.value("flagged_links", 0);
    summary.flagged_wrong_links = s.value("flagged_wrong_links", 0);
    summary.flagged_wrong_share = NumberField(s, "flagged_wrong_share");
    summary.unflagged_links = s.value("unflagged_links", 0);
    summary.unflagged_right_links = s.value("unflagged_right_links", 0);
    summary.unflagged_right_share = NumberField(s, "unflagged_right_share");
    summary.unflagged_usable_links = s.value("unflagged_usable_links", 0);
    summary.unflagged_usable_share = NumberField(s, "unflagged_usable_share");
    summary.unflagged_reversed_links = s.value("unflagged_reversed_links", 0);
  } catch (const json::exception& e) {
    throw InputError("evaluation '" + path + "' is malformed (" + e.what() + "); run `vmap eval` again");
  }
  return evaluation;
}

void EvaluationOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit({"max_rotation_error_deg", "--max-rotation-error", "Usable: rotation error below this (deg)"},
                max_rotation_error_deg);
  visitor.Visit({"max_translation_error_deg", "--max-translation-error",
                 "Usable: translation direction error below this (deg) where the parallax is enough"},
                max_translation_error_deg);
  visitor.Visit(
      {"min_parallax_px", "--min-parallax", "True parallax (px) from which the translation direction is judged"},
      min_parallax_px);
  visitor.Visit({"sampson_threshold_px", "--sampson-threshold",
                 "A match is on its true epipolar line within this Sampson error (px)"},
                sampson_threshold_px);
  visitor.Visit({"max_time_difference", "--max-time-difference",
                 "Seconds between a key image and its ground-truth pose (tum, euroc)"},
                max_time_difference);
}

}  // namespace vmap
