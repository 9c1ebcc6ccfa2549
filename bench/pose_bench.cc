// The pose estimators of a link, side by side on the same links against ground truth:
//   pose_bench MAP_DIR [MAP_DIR ...]
// Each map (built by `vmap build`, with a camera and ground truth beside its input) has its links analysed
// again with each variant below; the usable share, the median errors and the time per link are printed.
// Key images do not depend on the pose, so every variant sees the same links.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "vmap/core/runtime.h"
#include "vmap/evaluation/evaluation_inputs.h"
#include "vmap/evaluation/map_evaluation.h"
#include "vmap/map/map_io.h"
#include "vmap/mapping/link_analysis.h"

namespace {

struct Variant {
  std::string name;
  vmap::LinkAnalysisOptions options;
};

std::vector<Variant> Variants() {
  std::vector<Variant> variants;
  vmap::LinkAnalysisOptions o;
  o.pose.method = vmap::PoseMethod::kFromFundamental;
  variants.push_back({"F, then E = K^T F K (the verifier's F)", o});
  o = vmap::LinkAnalysisOptions();
  o.pose.use_all_matches = false;
  o.pose.starts = 1;
  o.pose.refine = false;
  o.pose.start_from_fundamental = false;
  variants.push_back({"E (USAC) on F's inliers", o});
  o.pose.use_all_matches = true;
  variants.push_back({"E (USAC) on all tentative matches", o});
  o.pose.refine = true;
  variants.push_back({"  + refinement", o});
  o.pose.start_from_fundamental = true;
  variants.push_back({"  + F's pose as a second start", o});
  o = vmap::LinkAnalysisOptions();
  variants.push_back({"  + 3 USAC starts (default)", o});
  for (const double threshold : {0.5, 2.0}) {
    o = vmap::LinkAnalysisOptions();
    o.pose.threshold = threshold;
    char name[64];
    std::snprintf(name, sizeof(name), "default, pose threshold %.1f px", threshold);
    variants.push_back({name, o});
  }
  return variants;
}

std::string Number(double value, int decimals) {
  if (!std::isfinite(value)) return "-";
  char text[32];
  std::snprintf(text, sizeof(text), "%.*f", decimals, value);
  return text;
}

}  // namespace

int main(int argc, char** argv) {
  vmap::InitializeRuntime();  // the process set up as the vmap binary has it (core/runtime.h)
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s MAP_DIR [MAP_DIR ...]\n", argv[0]);
    return 2;
  }
  for (int a = 1; a < argc; ++a) {
    const vmap::VisualMap map = vmap::ReadMap(argv[a]);
    const vmap::GroundTruth truth = vmap::MapGroundTruth(map, "", vmap::GroundTruthFormat::kAuto);
    const vmap::Camera camera = vmap::EvaluationCamera(map, "");
    std::printf("\n%s (%s, %zu links)\n\n", argv[a], map.input.path.c_str(), map.links.size());
    std::printf(
        "| pose estimator | usable links | rotation error, median (deg) | translation error, median (deg) | "
        "ms per link |\n|---|---:|---:|---:|---:|\n");
    for (const Variant& variant : Variants()) {
      vmap::VisualMap copy = map;
      copy.input.camera = camera;
      const auto start = std::chrono::steady_clock::now();
      vmap::AnalyzeLinks(copy, variant.options, 1);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const vmap::MapEvaluation e = vmap::EvaluateMap(copy, truth, camera, vmap::EvaluationOptions());
      std::printf("| %s | %d of %d (%s%%) | %s | %s | %s |\n", variant.name.c_str(), e.summary.usable_links,
                  e.summary.evaluated_links, Number(100.0 * e.summary.usable_share, 1).c_str(),
                  Number(e.summary.rotation_error_deg_median, 3).c_str(),
                  Number(e.summary.translation_error_deg_median, 2).c_str(),
                  Number(1e3 * seconds / std::max<size_t>(1, copy.links.size()), 1).c_str());
    }
  }
  return 0;
}
