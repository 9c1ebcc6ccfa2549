// The measurement behind "Denser poses alone are not safe" (docs/link-poses.md): a copy of a map whose links'
// matches, F and analysis all come from FEATURES ORB features per key image, extracted anew from the map's key
// images, with no cross-check against the link's own estimate. `vmap eval OUT` then judges them.
// usage: dense_link_pose MAP OUT FEATURES
#include <cstdio>
#include <filesystem>
#include <string>

#include "vmap/features/orb_matcher.h"
#include "vmap/map/map_io.h"
#include "vmap/mapping/key_image_selector.h"
#include "vmap/mapping/link_analysis.h"

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
    const vmap::Link again = vmap::MakeLink(vmap::ComparePair(*matcher, *matcher->Extract(a), *matcher->Extract(b),
                                                              verifier, vmap::SimilarityMode::kInlierRatio),
                                            link.from_key, link.to_key, link.below_tau);
    if (!again.has_fundamental) continue;
    link = again;
    vmap::AnalyzeLink(link, camera, analysis);
  }
  fs::create_directories(out);
  fs::remove_all(out / "keys");
  fs::copy(in / "keys", out / "keys", fs::copy_options::recursive);
  vmap::WriteMapFiles(map, out);
  std::printf("%zu links\n", map.links.size());
}
