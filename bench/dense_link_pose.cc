// The measurement behind "Denser poses alone are not safe" (docs/link-poses.md): a copy of a map whose links'
// matches, F and analysis all come from FEATURES ORB features per key image, extracted anew from the map's key
// images, with no cross-check against the link's own estimate. `vmap eval OUT` then judges them.
// usage: dense_link_pose MAP OUT FEATURES
#include <cstdio>
#include <filesystem>
#include <string>

#include "vmap/features/orb_matcher.h"
#include "vmap/map/map_io.h"
#include "vmap/mapping/link_analysis.h"
#include "vmap/mapping/pair_match.h"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s MAP OUT FEATURES\n", argv[0]);
    return 2;
  }
  namespace fs = std::filesystem;
  const fs::path in = argv[1], out = argv[2];
  vmap::VisualMap map = vmap::ReadMap(in);
  vmap::OrbMatcherOptions orb;
  orb.num_features = std::stoi(argv[3]);
  const auto matcher = vmap::CreateOrbMatcher(orb);
  vmap::VerifierOptions verifier;
  const vmap::LinkAnalysisOptions analysis;
  const vmap::Camera* camera = map.input.camera ? &*map.input.camera : nullptr;
  for (vmap::Link& link : map.links) {
    if (!link.has_fundamental) continue;
    const cv::Mat a = vmap::ReadKeyImage(in, map.key_images[link.from_key], true);
    const cv::Mat b = vmap::ReadKeyImage(in, map.key_images[link.to_key], true);
    const vmap::PairMatch pm = vmap::MatchPair(*matcher, vmap::PairImage(a), vmap::PairImage(b), verifier);
    if (!pm.fundamental.success) continue;
    std::vector<vmap::Correspondence> verified, rejected;
    for (size_t i = 0; i < pm.matches.size(); ++i) {
      (pm.fundamental.inlier_mask[i] ? verified : rejected).push_back({pm.matches.points0[i], pm.matches.points1[i]});
    }
    link.num_tentative = static_cast<int>(pm.matches.size());
    link.num_verified = static_cast<int>(verified.size());
    link.F = pm.fundamental.F;
    link.correspondences = verified;
    link.correspondences.insert(link.correspondences.end(), rejected.begin(), rejected.end());
    vmap::AnalyzeLink(link, camera, analysis);
  }
  fs::create_directories(out);
  fs::remove_all(out / "keys");
  fs::copy(in / "keys", out / "keys", fs::copy_options::recursive);
  vmap::WriteMapFiles(map, out);
  std::printf("%zu links\n", map.links.size());
}
