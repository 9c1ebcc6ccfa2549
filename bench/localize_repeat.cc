// A teach run and a repeat run of one place, judged with ground truth (docs/measurements/localization.md).
//
//   localize_repeat TUM_SEQUENCE --teach FIRST:LAST --repeat FIRST:LAST [--stride N]
//                   [--max-distance M] [--max-angle DEG] [--acceptance chance,counts]
//                   [--variants counts/0/0,chance/0.5/0.25] [--orb-fast-threshold T] [--orb-features N]
//                   [--no-window-matching 1]
//
// Builds a map of the teach frames (default options) and localizes the repeat frames against it. The
// sequence's groundtruth.txt (TUM: timestamp tx ty tz qx qy qz qw, camera to world) judges each repeat frame:
//  - it is coverable when some key image was taken within --max-distance metres (default 0.5) with a viewing
//    direction within --max-angle degrees (default 30) of it;
//  - a localized frame is right when its key image or the next one is within those bounds, wrong otherwise.
// Prints the counts, and the stretches of repeat frames that were lost although coverable. With several
// acceptance rules (--acceptance, comma-separated; default: the localizer's defaults) or variants (--variants
// RULE/RECHECK/SHARE,...: bench/localizer_variants.h) the map is built once and the repeat run localized once
// per variant, one after the other.

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>

#include "vmap/core/runtime.h"
#include "vmap/features/matcher_registry.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/localization/localization_map.h"
#include "vmap/localization/localize_sequence.h"
#include "vmap/map/map_io.h"

#include "bench_map.h"
#include "localizer_variants.h"

namespace fs = std::filesystem;
using namespace vmap;

namespace {

struct Pose {
  cv::Vec3d position;
  cv::Vec3d forward;  // the camera's viewing direction (its z axis) in the world
};

// groundtruth.txt by timestamp.
std::map<double, Pose> ReadGroundTruth(const fs::path& file) {
  std::map<double, Pose> poses;
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double t, x, y, z, qx, qy, qz, qw;
    if (!(fields >> t >> x >> y >> z >> qx >> qy >> qz >> qw)) continue;
    // Third column of the rotation matrix of the unit quaternion.
    const cv::Vec3d forward(2 * (qx * qz + qy * qw), 2 * (qy * qz - qx * qw), 1 - 2 * (qx * qx + qy * qy));
    poses[t] = {{x, y, z}, forward};
  }
  return poses;
}

const Pose* PoseAt(const std::map<double, Pose>& poses, double t) {
  auto it = poses.lower_bound(t - 1e-3);
  if (it == poses.end() || std::abs(it->first - t) > 0.02) return nullptr;
  return &it->second;
}

bool Near(const Pose& a, const Pose& b, double max_distance, double max_angle_deg) {
  const double cosine = a.forward.dot(b.forward) / (cv::norm(a.forward) * cv::norm(b.forward));
  return cv::norm(a.position - b.position) <= max_distance &&
         std::acos(std::clamp(cosine, -1.0, 1.0)) * 180.0 / M_PI <= max_angle_deg;
}

std::pair<int, int> Range(const std::string& text) {
  int first = 0, last = -1;
  std::sscanf(text.c_str(), "%d:%d", &first, &last);
  return {first, last};
}

// Localizes the repeat frames with `localizer_options` and prints what the ground truth says of them.
void Judge(const fs::path& sequence, const LocalizationMap& opened, const LocalizerOptions& localizer_options,
           std::pair<int, int> repeat, int stride, const std::map<double, Pose>& poses, double max_distance,
           double max_angle) {
  const VisualMap& map = opened.map;
  Localizer localizer(map, opened.keys, *opened.matcher, localizer_options);
  FrameSourceOptions repeat_options;
  repeat_options.first = repeat.first;
  repeat_options.last = repeat.second;
  repeat_options.stride = stride;
  auto source = OpenFrameSource(sequence.string(), repeat_options);
  LocalizeSequenceOptions run;
  run.show_progress = false;
  long coverable = 0, right = 0, wrong = 0, lost_coverable = 0, lost_uncoverable = 0, ranked_near = 0,
       lost_tracking = 0, right_steered = 0, wrong_steered = 0, uncertain = 0;
  std::vector<std::pair<int, int>> lost_stretches;  // coverable frames lost, as [first, last] runs
  std::vector<std::string> wrongs;
  const LocalizationSummary summary =
      LocalizeSequence(*source, *opened.matcher, localizer, run, [&](const Frame& frame, const LocalizationResult& r) {
        const Pose* pose = PoseAt(poses, frame.timestamp);
        if (!pose) return;
        auto key_near = [&](int key) {
          if (key < 0) return false;
          const Pose* key_pose = PoseAt(poses, map.key_images[key].timestamp);
          return key_pose && Near(*pose, *key_pose, max_distance, max_angle);
        };
        bool can = false;
        for (int k = 0; k < static_cast<int>(map.key_images.size()) && !can; ++k) can = key_near(k);
        coverable += can;
        if (r.status == LocalizationStatus::kLost) {
          if (can) {
            ++lost_coverable;
            lost_tracking += r.candidates.empty();
            // Did the ranking propose a key image taken near this frame (then verification refused it)?
            bool proposed = false;
            for (const RelocalizationCandidate& c : r.candidates) proposed = proposed || key_near(c.key);
            ranked_near += proposed;
            if (!lost_stretches.empty() && lost_stretches.back().second >= frame.source_index - stride) {
              lost_stretches.back().second = frame.source_index;
            } else {
              lost_stretches.push_back({frame.source_index, frame.source_index});
            }
          } else {
            ++lost_uncoverable;
          }
        } else if (key_near(r.key) || key_near(r.next_key)) {
          ++right;
          right_steered += MaySteerBy(r);
        } else {
          ++wrong;
          wrong_steered += MaySteerBy(r);
          if (wrongs.size() < 10) {
            wrongs.push_back(std::to_string(frame.source_index) + "->key " + std::to_string(r.key) + " (frame " +
                             std::to_string(map.key_images[r.key].source_index) + ", " +
                             LocalizationStatusName(r.status) + ")");
          }
        }
        uncertain += r.status == LocalizationStatus::kUncertain;
      });
  std::printf(
      "repeat frames %ld: coverable %ld; localized right %ld, wrong %ld; lost %ld (coverable %ld, not "
      "coverable %ld); tracking %ld, relocalized %ld; %.1f frames/s\n",
      summary.frames, coverable, right, wrong, summary.lost, lost_coverable, lost_uncoverable, summary.tracking,
      summary.relocalized, summary.frames_per_second);
  std::printf("steered by (tracking or relocalized): right %ld, wrong %ld; uncertain %ld\n", right_steered,
              wrong_steered, uncertain);
  std::printf(
      "lost though coverable: %ld while tracking (before the estimate is dropped), %ld relocalizing: the "
      "ranking proposed a key image near the frame for %ld (verification refused it), none for %ld\n",
      lost_tracking, lost_coverable - lost_tracking, ranked_near, lost_coverable - lost_tracking - ranked_near);
  for (const auto& [a, b] : lost_stretches) std::printf("  lost though coverable: frames %d-%d\n", a, b);
  for (const std::string& w : wrongs) std::printf("  wrong: %s\n", w.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  // CLI11, as the vmap binary parses its flags: a flag it does not know, or one without its value, is an error.
  CLI::App app{
      "localize_repeat: a map of a TUM sequence's teach frames, its repeat frames localized and judged by the "
      "ground truth"};
  fs::path sequence;
  MatcherOptions matcher_options;  // ORB with its defaults unless --orb-fast-threshold / --orb-features
  std::string teach_range = "0:499", repeat_range = "500:999", acceptance, variant_list;
  int stride = 1;
  double max_distance = 0.5, max_angle = 30.0;
  std::string ranking = "auto";
  bool window_matching = LocalizerOptions().window_matching;
  int descriptors = RankingOptions().max_descriptors_per_key, candidates = LocalizerOptions().relocalization_candidates;
  app.add_option("sequence", sequence, "the TUM RGB-D sequence (with groundtruth.txt)")->required();
  const auto is_range = [](const std::string& text) -> std::string {
    int first = 0, last = 0;
    char rest = 0;
    return std::sscanf(text.c_str(), "%d:%d%c", &first, &last, &rest) == 2 ? "" : "expects FIRST:LAST, e.g. 0:499";
  };
  app.add_option("--teach", teach_range, "the teach frames, A:B")->check(is_range);
  app.add_option("--repeat", repeat_range, "the repeat frames, C:D")->check(is_range);
  app.add_option("--stride", stride, "every n-th frame");
  app.add_option("--max-distance", max_distance, "a key image is right within this distance (m)");
  app.add_option("--max-angle", max_angle, "and this angle (degrees)");
  app.add_option("--ranking", ranking, "the key image ranking");
  app.add_option("--descriptors", descriptors, "the ranking's descriptors per key image");
  app.add_option("--candidates", candidates, "relocalization candidates");
  app.add_option("--acceptance", acceptance, "acceptance variants to compare: chance,counts");
  app.add_option("--variants", variant_list, "localizer variants to compare: RULE/RECHECK/SHARE,...");
  app.add_flag("!--no-window-matching", window_matching, "no matching by the prediction's window");
  app.add_option("--orb-fast-threshold", matcher_options.Of<OrbMatcherOptions>().fast_threshold,
                 "ORB's FAST threshold");
  app.add_option("--orb-features", matcher_options.Of<OrbMatcherOptions>().num_features, "the map's ORB features");
  CLI11_PARSE(app, argc, argv);
  const std::pair<int, int> teach = Range(teach_range), repeat = Range(repeat_range);
  const std::vector<bench::LocalizerVariant> variants = bench::VariantsToCompare(acceptance, variant_list);
  vmap::InitializeRuntime();  // the process set up as the vmap binary has it (core/runtime.h)
  const auto poses = ReadGroundTruth(sequence / "groundtruth.txt");
  if (poses.empty()) {
    std::fprintf(stderr, "localize_repeat: no poses in %s\n", (sequence / "groundtruth.txt").c_str());
    return 2;
  }
  const fs::path map_directory = fs::temp_directory_path() / ("vmap_localize_repeat_" + std::to_string(getpid()));
  FrameSourceOptions teach_frames;
  teach_frames.first = teach.first;
  teach_frames.last = teach.second;
  LocalizationMap opened = bench::BuildAndOpenMap(sequence.string(), teach_frames, matcher_options, {}, map_directory);
  const VisualMap& map = opened.map;
  std::printf(
      "teach frames %d-%d: %zu key images; repeat frames %d-%d (stride %d); near = within %.2f m and %.0f deg\n",
      teach.first, teach.second, map.key_images.size(), repeat.first, repeat.second, stride, max_distance, max_angle);

  for (const bench::LocalizerVariant& variant : variants) {
    std::printf("--- %s\n", variant.Name().c_str());
    LocalizerOptions localizer_options = MapLocalizerOptions(opened);
    variant.ApplyTo(localizer_options);
    localizer_options.ranking.method = ParseRankingMethod(ranking);
    localizer_options.ranking.max_descriptors_per_key = descriptors;
    localizer_options.relocalization_candidates = candidates;
    localizer_options.window_matching = window_matching;
    Judge(sequence, opened, localizer_options, repeat, stride, poses, max_distance, max_angle);
  }
  fs::remove_all(map_directory);
  return 0;
}
