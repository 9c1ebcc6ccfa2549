// Every frame of a query against every key image of a map, as the localizer compares them (Localizer::Compare):
// the evidence a belief over the route weighs, one CSV row per (frame, key image). The input of the calibration of
// the route belief's evidence (bench/route_conditions.py --evidence-dir, docs/localize.md).
//
//   evidence_dump MAP QUERY [--stride N] [--last N] [--cross-check 0|1] [--ratio R] [--frame-fast T]
//                 [--frame-features N] [--frame-edge PX] [--frame-grid-cell PX] [--frame-min-fast T] [--frame-clahe C]
//
// Columns: frame, source_index, key, matched, accepted, tentative, verified, similarity, log10_nfa, link_verified
// (the smaller of the verified matches of the key image's links with its neighbours in the map; 0 without),
// heading_confidence, heading_votes.

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "vmap/core/runtime.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/localization/localization_map.h"
#include "vmap/sources/frame_source.h"

using namespace vmap;

int main(int argc, char** argv) {
  InitializeRuntime();  // the process set up as the vmap binary has it (core/runtime.h)
  if (argc < 3) {
    std::fprintf(stderr, "usage: evidence_dump MAP QUERY [--stride N] [--last N]\n");
    return 2;
  }
  FrameSourceOptions query_options;
  // ORB only, an experiment (docs/localize.md, "guided matching"): the frame's features and the matching of the
  // comparisons made with other options than the map's (OrbMatcherOptions' defaults otherwise).
  OrbMatcherOptions frame_orb, match_orb;
  bool orb_override = false;
  for (int i = 3; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--stride")) query_options.stride = std::stoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--last")) query_options.last = std::stoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--cross-check"))
      match_orb.cross_check = std::stoi(argv[i + 1]) != 0, orb_override = true;
    if (!std::strcmp(argv[i], "--ratio")) match_orb.ratio = std::stod(argv[i + 1]), orb_override = true;
    if (!std::strcmp(argv[i], "--frame-fast")) frame_orb.fast_threshold = std::stoi(argv[i + 1]), orb_override = true;
    if (!std::strcmp(argv[i], "--frame-features")) frame_orb.num_features = std::stoi(argv[i + 1]), orb_override = true;
    if (!std::strcmp(argv[i], "--frame-edge")) frame_orb.edge_threshold = std::stoi(argv[i + 1]), orb_override = true;
    if (!std::strcmp(argv[i], "--frame-grid-cell")) frame_orb.grid_cell = std::stoi(argv[i + 1]), orb_override = true;
    if (!std::strcmp(argv[i], "--frame-min-fast"))
      frame_orb.min_fast_threshold = std::stoi(argv[i + 1]), orb_override = true;
    if (!std::strcmp(argv[i], "--frame-clahe")) frame_orb.clahe_clip = std::stod(argv[i + 1]), orb_override = true;
  }
  const LocalizationMap opened = OpenLocalizationMap(argv[1], {});
  query_options.resize = QueryResize(opened.map, "");
  const LocalizerOptions options = FollowMap(opened, MapLocalizerOptions(opened), query_options.resize);
  const std::unique_ptr<Matcher> frame_matcher = orb_override ? CreateOrbMatcher(frame_orb) : nullptr;
  const std::unique_ptr<Matcher> match_matcher = orb_override ? CreateOrbMatcher(match_orb) : nullptr;
  const Localizer localizer(opened.map, opened.keys, orb_override ? *match_matcher : *opened.matcher, options);
  const int num_keys = static_cast<int>(opened.map.key_images.size());
  std::vector<int> link_verified(num_keys, 0);
  for (const Link& link : opened.map.links) {
    if (!link.has_fundamental || link.num_verified <= 0) continue;
    for (const int k : {link.from_key, link.to_key}) {
      link_verified[k] = link_verified[k] > 0 ? std::min(link_verified[k], link.num_verified) : link.num_verified;
    }
  }
  auto source = OpenFrameSource(argv[2], query_options);
  std::printf(
      "frame,source_index,key,matched,accepted,tentative,verified,similarity,log10_nfa,link_verified,"
      "heading_confidence,heading_votes\n");
  while (const std::optional<Frame> next = source->Next()) {
    const Frame& frame = *next;
    const auto features = (orb_override ? *frame_matcher : *opened.matcher).Extract(frame.gray);
    for (int k = 0; k < num_keys; ++k) {
      const KeyComparison c = localizer.Compare(*features, k);
      std::printf("%d,%d,%d,%d,%d,%d,%d,%.4f,%.3f,%d,%.4f,%d\n", frame.index, frame.source_index, k, c.matched ? 1 : 0,
                  c.accepted ? 1 : 0, c.num_tentative, c.num_verified, c.similarity, std::min(c.log10_nfa, 1e9),
                  link_verified[k], c.heading.confidence, c.heading.votes);
    }
  }
  return 0;
}
