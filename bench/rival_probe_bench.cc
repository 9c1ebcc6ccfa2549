// What the rival test's probes cost beside the pose estimate they follow (docs/link-poses.md):
//   rival_probe_bench MAP_DIR [MAP_DIR ...]
// Each map (built by `vmap build`, with a camera) has every link's pose estimated again as a map's link gets it
// (EstimateRelativePose from its starts and the pose of F), then probed (ProbeTranslation at twice the rival
// angle); the time per link of each is printed, measured on a second pass so that caches are warm.

#include <chrono>
#include <cstdio>
#include <vector>

#include "vmap/geometry/translation_evidence.h"
#include "vmap/map/map_io.h"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: rival_probe_bench MAP_DIR [MAP_DIR ...]\n");
    return 2;
  }
  using Clock = std::chrono::steady_clock;
  for (int a = 1; a < argc; ++a) {
    const vmap::VisualMap map = vmap::ReadMap(argv[a]);
    if (!map.input.camera) {
      std::fprintf(stderr, "vmap: error: %s has no camera: build it from an input with intrinsics\n", argv[a]);
      return 2;
    }
    const vmap::Camera& camera = *map.input.camera;
    const vmap::PoseOptions pose_options;
    const double probe_angle = 2.0 * vmap::TranslationOptions().rival_angle_deg;
    double estimate_seconds = 0.0, probe_seconds = 0.0;
    int links = 0;
    for (int pass = 0; pass < 2; ++pass) {
      for (const vmap::Link& link : map.links) {
        if (!link.has_fundamental) continue;
        std::vector<cv::Point2f> verified_from, verified_to, all_from, all_to;
        for (size_t i = 0; i < link.correspondences.size(); ++i) {
          const vmap::Correspondence& c = link.correspondences[i];
          if (static_cast<int>(i) < link.num_verified) {
            verified_from.push_back(c.p0);
            verified_to.push_back(c.p1);
          }
          all_from.push_back(c.p0);
          all_to.push_back(c.p1);
        }
        const auto t0 = Clock::now();
        const vmap::RelativePose pose =
            vmap::EstimateRelativePose(camera, all_from, all_to, pose_options,
                                       {vmap::PoseFromFundamental(link.F, camera, verified_from, verified_to)});
        const auto t1 = Clock::now();
        const std::vector<vmap::PoseMinimum> probes =
            vmap::ProbeTranslation(pose, camera, all_from, all_to, pose_options, probe_angle);
        const auto t2 = Clock::now();
        if (pass == 0) continue;
        estimate_seconds += std::chrono::duration<double>(t1 - t0).count();
        probe_seconds += std::chrono::duration<double>(t2 - t1).count();
        ++links;
      }
    }
    if (links == 0) continue;
    std::printf("%s: %d links, estimate %.2f ms/link, probes %.2f ms/link (+%.0f%%)\n", argv[a], links,
                1e3 * estimate_seconds / links, 1e3 * probe_seconds / links, 100.0 * probe_seconds / estimate_seconds);
  }
  return 0;
}
