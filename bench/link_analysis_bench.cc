// Times the per-link analysis (relative pose, parallax, homography test) on the links of existing maps:
//   link_analysis_bench MAP_DIR [MAP_DIR ...]
// Each map's links are analysed again with the default options, stage by stage, 3 times; the median is printed.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "vmap/geometry/homography.h"
#include "vmap/geometry/relative_pose.h"
#include "vmap/mapping/link_analysis.h"
#include "vmap/mapping/map_io.h"

namespace {

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double MedianOf(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s MAP_DIR [MAP_DIR ...]\n", argv[0]);
    return 2;
  }
  vmap::LinkAnalysisOptions options;
  const char* variant = std::getenv("VARIANT");
  if (variant && std::string(variant) == "1norefine") { options.pose.starts = 1; options.pose.refine = false; }
  if (variant && std::string(variant) == "3norefine") { options.pose.refine = false; }
  if (variant && std::string(variant) == "1refine") { options.pose.starts = 1; }
  for (int a = 1; a < argc; ++a) {
    const vmap::VisualMap map = vmap::ReadMap(argv[a]);
    if (!map.input.camera) {
      std::printf("%s: no camera, skipped\n", argv[a]);
      continue;
    }
    const vmap::Camera& camera = *map.input.camera;
    std::vector<double> pose_s, homography_s, total_s;
    for (int repeat = 0; repeat < 3; ++repeat) {
      double pose = 0, homography = 0;
      auto all = std::chrono::steady_clock::now();
      for (const vmap::Link& link : map.links) {
        if (!link.has_fundamental) continue;
        std::vector<cv::Point2f> from, to, vfrom, vto;
        for (size_t i = 0; i < link.correspondences.size(); ++i) {
          from.push_back(link.correspondences[i].p0);
          to.push_back(link.correspondences[i].p1);
          if (static_cast<int>(i) < link.num_verified) {
            vfrom.push_back(link.correspondences[i].p0);
            vto.push_back(link.correspondences[i].p1);
          }
        }
        auto start = std::chrono::steady_clock::now();
        const std::vector<vmap::RelativePose> extra = {vmap::PoseFromFundamental(link.F, camera, vfrom, vto)};
        vmap::EstimateRelativePose(camera, from, to, options.pose, extra);
        pose += Seconds(start);
        start = std::chrono::steady_clock::now();
        vmap::CheckHomography(vfrom, vto, options.homography);
        homography += Seconds(start);
      }
      total_s.push_back(Seconds(all));
      pose_s.push_back(pose);
      homography_s.push_back(homography);
    }
    const double n = std::max<size_t>(1, map.links.size());
    std::printf("%s: %zu links; per link: pose %.2f ms, homography %.2f ms, all %.2f ms\n", argv[a], map.links.size(),
                1e3 * MedianOf(pose_s) / n, 1e3 * MedianOf(homography_s) / n, 1e3 * MedianOf(total_s) / n);
  }
  return 0;
}
