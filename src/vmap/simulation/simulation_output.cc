#include "vmap/simulation/simulation_output.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "vmap/core/options_json.h"

namespace vmap {

namespace {

// `value` to a multiple of `unit` (a power of ten at most 1), written in as few digits.
double Rounded(double value, double unit = 1e-3) {
  const double per_unit = std::round(1.0 / unit);
  return std::isfinite(value) ? std::round(value * per_unit) / per_unit : value;
}

nlohmann::json Number(double value, double unit = 1e-3) {
  if (!std::isfinite(value)) return nullptr;
  return Rounded(value, unit);
}

nlohmann::json Points(const std::vector<cv::Point2d>& points) {
  nlohmann::json list = nlohmann::json::array();
  for (const cv::Point2d& p : points) list.push_back({Rounded(p.x), Rounded(p.y)});
  return list;
}

}  // namespace

nlohmann::json SimulationJson(const SimulationResult& result, const SimulationOptions& options) {
  nlohmann::json json;
  json["route"] = {{"name", result.route.name},
                   {"length_m", Rounded(result.route.path.length())},
                   {"closed_corridor", result.route.corridor.closed()},
                   {"path", Points(result.route.path.points())},
                   {"corridor", Points(result.route.corridor.points())}};
  json["options"] = OptionsToJson(options);
  json["matcher"] = result.matcher;
  nlohmann::json keys = nlohmann::json::array();
  for (const Pose2d& pose : result.key_image_poses)
    keys.push_back({Rounded(pose.x), Rounded(pose.y), Rounded(pose.yaw)});
  json["teach"] = {{"frames", result.teach_frames},
                   {"key_images", result.key_images},
                   {"seconds", Rounded(result.teach_seconds)},
                   {"key_image_poses", keys}};
  const SimulationSummary& s = result.summary;
  json["summary"] = {{"trials", s.trials},
                     {"successes", s.successes},
                     {"success_rate", Rounded(s.success_rate, 1e-4)},
                     {"mean_final_error_m", Number(s.mean_final_error)},
                     {"mean_lateral_rms_second_half_m", Number(s.mean_lateral_rms_second_half)},
                     {"worst_lateral_rms_second_half_m", Number(s.worst_lateral_rms_second_half)},
                     {"share_converged", Rounded(s.share_converged, 1e-4)},
                     {"frames", s.frames},
                     {"frames_lost", s.frames_lost},
                     {"mean_step_ms", Number(1e3 * s.mean_step_seconds, 1e-2)},
                     {"max_step_ms", Number(1e3 * s.max_step_seconds, 1e-2)},
                     {"render_frames_per_second", Number(s.render_frames_per_second, 0.1)},
                     {"seconds", Rounded(result.seconds, 0.01)}};
  nlohmann::json trials = nlohmann::json::array();
  for (const TrialResult& trial : result.trials) {
    nlohmann::json t = {{"index", trial.index},
                        {"start_lateral_m", Rounded(trial.start_lateral)},
                        {"start_heading_deg", Rounded(trial.start_heading_deg, 0.01)},
                        {"success", trial.success},
                        {"reached_goal", trial.reached_goal},
                        {"end", trial.end},
                        {"final_error_m", Number(trial.final_error)},
                        {"lateral_rms_second_half_m", Number(trial.lateral_rms_second_half)},
                        {"lateral_max_second_half_m", Number(trial.lateral_max_second_half)},
                        {"lateral_max_m", Number(trial.lateral_max)},
                        {"settled_at_m", Number(trial.settled_at)},
                        {"frames", trial.frames},
                        {"frames_lost", trial.frames_lost},
                        {"mean_step_ms", Number(1e3 * trial.mean_step_seconds, 1e-2)},
                        {"max_step_ms", Number(1e3 * trial.max_step_seconds, 1e-2)},
                        {"mean_render_ms", Number(1e3 * trial.mean_render_seconds, 1e-2)},
                        {"duration_s", Rounded(trial.duration, 0.01)}};
    nlohmann::json columns;
    for (const char* name : {"t",
                             "x",
                             "y",
                             "yaw",
                             "s",
                             "lateral",
                             "v",
                             "w",
                             "key",
                             "status",
                             "state",
                             "steering",
                             "heading_offset",
                             "bearing",
                             "line_angle",
                             "true_bearing",
                             "true_line_angle",
                             "translation_sigma_deg",
                             "target_verified",
                             "lateral_estimate",
                             "bearings_taken",
                             "measurements_refused",
                             "heading_error_estimate",
                             "headings_taken",
                             "unassociated",
                             "arc_estimate",
                             "key_log_scale",
                             "pose_bearing",
                             "pose_heading",
                             "scales_taken"}) {
      columns[name] = nlohmann::json::array();
    }
    for (const TrialSample& sample : trial.samples) {
      columns["t"].push_back(Rounded(sample.time, 0.01));
      columns["x"].push_back(Rounded(sample.pose.x));
      columns["y"].push_back(Rounded(sample.pose.y));
      columns["yaw"].push_back(Rounded(sample.pose.yaw, 1e-4));
      columns["s"].push_back(Rounded(sample.s));
      columns["lateral"].push_back(Rounded(sample.lateral));
      columns["v"].push_back(Rounded(sample.command.linear));
      columns["w"].push_back(Rounded(sample.command.angular));
      columns["key"].push_back(sample.key);
      columns["status"].push_back(LocalizationStatusName(sample.status));
      columns["state"].push_back(ControllerStateName(sample.state));
      columns["steering"].push_back(sample.steering);
      columns["heading_offset"].push_back(Number(sample.heading_offset, 1e-4));
      columns["bearing"].push_back(Number(sample.bearing, 1e-4));
      columns["line_angle"].push_back(Number(sample.line_angle, 1e-4));
      columns["true_bearing"].push_back(Number(sample.true_bearing, 1e-4));
      columns["true_line_angle"].push_back(Number(sample.true_line_angle, 1e-4));
      columns["translation_sigma_deg"].push_back(Number(sample.translation_sigma_deg, 0.01));
      columns["target_verified"].push_back(sample.target_verified);
      columns["lateral_estimate"].push_back(Number(sample.lateral_estimate));
      columns["bearings_taken"].push_back(sample.observation.bearings);
      columns["measurements_refused"].push_back(sample.observation.refused);
      columns["heading_error_estimate"].push_back(Number(sample.heading_error_estimate, 1e-4));
      columns["headings_taken"].push_back(sample.observation.headings);
      columns["unassociated"].push_back(sample.observation.unassociated);
      columns["arc_estimate"].push_back(Number(sample.arc_estimate));
      columns["key_log_scale"].push_back(Number(sample.key_log_scale, 1e-4));
      columns["pose_bearing"].push_back(Number(sample.pose_bearing, 1e-4));
      columns["pose_heading"].push_back(Number(sample.pose_heading, 1e-4));
      columns["scales_taken"].push_back(sample.observation.scales);
    }
    t["samples"] = columns;
    trials.push_back(t);
  }
  json["trials"] = trials;
  return json;
}

cv::Mat DrawTopView(const SimulationResult& result, const SimulationOptions& options, int width) {
  const RoutePath& corridor = result.route.corridor;
  const double half = 0.5 * options.corridor.width;
  // Bounds of the corridor with its walls.
  double min_x = 1e18, max_x = -1e18, min_y = 1e18, max_y = -1e18;
  for (const cv::Point2d& p : corridor.points()) {
    min_x = std::min(min_x, p.x - half), max_x = std::max(max_x, p.x + half);
    min_y = std::min(min_y, p.y - half), max_y = std::max(max_y, p.y + half);
  }
  const double margin = 0.5;
  min_x -= margin, min_y -= margin, max_x += margin, max_y += margin;
  const double scale = width / (max_x - min_x);
  const int height = std::max(100, static_cast<int>(std::ceil((max_y - min_y) * scale)));
  cv::Mat image(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  auto to_pixel = [&](double x, double y) {
    return cv::Point(static_cast<int>(std::lround((x - min_x) * scale * 16)),
                     static_cast<int>(std::lround((max_y - y) * scale * 16)));
  };
  auto polyline = [&](const std::vector<cv::Point2d>& points, bool closed, cv::Scalar colour, int thickness) {
    std::vector<cv::Point> pixels;
    for (const cv::Point2d& p : points) pixels.push_back(to_pixel(p.x, p.y));
    cv::polylines(image, pixels, closed, colour, thickness, cv::LINE_AA, 4);
  };
  // The walls: the centre line offset by half the width on either side (sampled along it).
  for (const double side : {half, -half}) {
    std::vector<cv::Point2d> wall;
    const double step = 0.05;
    for (double s = 0.0; s <= corridor.length() + 1e-9; s += step) {
      const Pose2d pose = corridor.At(s);
      wall.emplace_back(pose.x - std::sin(pose.yaw) * side, pose.y + std::cos(pose.yaw) * side);
    }
    polyline(wall, corridor.closed(), cv::Scalar(90, 90, 90), 3);
  }
  polyline(result.route.path.points(), false, cv::Scalar(200, 120, 40), 2);
  for (const Pose2d& key : result.key_image_poses) {
    cv::circle(image, to_pixel(key.x, key.y), 3 * 16, cv::Scalar(200, 120, 40), cv::FILLED, cv::LINE_AA, 4);
  }
  for (const TrialResult& trial : result.trials) {
    std::vector<cv::Point2d> track;
    for (const TrialSample& sample : trial.samples) track.emplace_back(sample.pose.x, sample.pose.y);
    if (track.size() >= 2) polyline(track, false, trial.success ? cv::Scalar(60, 160, 40) : cv::Scalar(40, 40, 220), 1);
    if (!track.empty())
      cv::circle(image, to_pixel(track.back().x, track.back().y), 2 * 16, cv::Scalar(0, 0, 0), cv::FILLED, cv::LINE_AA,
                 4);
  }
  const Pose2d goal = result.route.path.At(result.route.path.length());
  cv::circle(image, to_pixel(goal.x, goal.y), static_cast<int>(options.goal_tolerance * scale * 16),
             cv::Scalar(0, 0, 0), 1, cv::LINE_AA, 4);
  return image;
}

}  // namespace vmap
