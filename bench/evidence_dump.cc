// Every frame of a query against every key image of a map, as the localizer compares them (Localizer::Compare):
// the evidence a belief over the route weighs, one CSV row per (frame, key image). The input of the calibration of
// the route belief's evidence (bench/route_conditions.py --evidence-dir, docs/localize.md).
//
//   evidence_dump MAP QUERY [--stride N] [--last N] [--cross-check 0|1] [--ratio R] [--frame-fast T]
//                 [--frame-features N] [--frame-edge PX] [--frame-grid-cell PX] [--frame-min-fast T] [--frame-clahe C]
//                 [--guided 1]
//
// Columns: frame, source_index, key, matched, accepted, tentative, verified, similarity, log10_nfa, link_verified
// (the smaller of the verified matches of the key image's links with its neighbours in the map; 0 without),
// heading_confidence, heading_votes, heading_px, heading_voters, and the continuity of the heading
// (docs/localize.md, "Continuity of the heading"): prev_heading_px, the previous frame's heading against the same key
// image (the prediction a tracking run has of this frame's; empty on the first frame or without a heading), and near_S
// / near_L, how many of this comparison's tentative matches move by the predicted displacement (dx within 1/80 or 1/40
// of the image's width of prev_heading_px, dy within 1/20 of its height of 0). With --guided 1 (ORB maps), the same key
// image matched again as the localizer's guided matching does (no cross check): g_tentative, g_verified, g_log10_nfa,
// g_heading_px, g_heading_votes, g_near_S, g_near_L (g_near_* against the same prediction).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "vmap/core/runtime.h"
#include "vmap/features/matcher_registry.h"
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
  bool orb_override = false, guided = false;
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
    if (!std::strcmp(argv[i], "--guided")) guided = std::stoi(argv[i + 1]) != 0;
  }
  const LocalizationMap opened = OpenLocalizationMap(argv[1], {});
  query_options.resize = QueryResize(opened.map, "");
  const LocalizerOptions options = FollowMap(opened, MapLocalizerOptions(opened), query_options.resize);
  const std::unique_ptr<Matcher> frame_matcher = orb_override ? CreateOrbMatcher(frame_orb) : nullptr;
  const std::unique_ptr<Matcher> match_matcher = orb_override ? CreateOrbMatcher(match_orb) : nullptr;
  const Localizer localizer(opened.map, opened.keys, orb_override ? *match_matcher : *opened.matcher, options);
  // As Localizer's guided matcher: the map's ORB options without the cross check.
  std::unique_ptr<Matcher> guided_matcher;
  if (guided) {
    MatcherOptions guided_options;
    guided_options.type = OrbMatcherOptions::kModelName;
    guided_options.model(guided_options.type)
        .FromJson(nlohmann::json::parse(opened.matcher->DescribeOptionsJson()), "the map's matcher");
    guided_options.Of<OrbMatcherOptions>().cross_check = false;
    guided_matcher = CreateMatcher(guided_options);
  }
  std::unique_ptr<Localizer> guided_localizer;
  if (guided) guided_localizer = std::make_unique<Localizer>(opened.map, opened.keys, *guided_matcher, options);
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
      "heading_confidence,heading_votes,heading_px,heading_voters,prev_heading_px,near_S,near_L%s\n",
      guided ? ",g_tentative,g_verified,g_log10_nfa,g_heading_px,g_heading_votes,g_near_S,g_near_L" : "");
  std::vector<double> previous_heading(num_keys, std::nan("")), heading(num_keys, std::nan(""));
  // How many tentative matches frame -> key image move by (predicted_dx, 0) within the window.
  auto near = [](const TentativeMatches& m, cv::Size size, double predicted_dx, double share_x) {
    if (!std::isfinite(predicted_dx)) return -1;
    int count = 0;
    for (size_t i = 0; i < m.size(); ++i) {
      const double dx = m.points0[i].x - m.points1[i].x, dy = m.points0[i].y - m.points1[i].y;
      count += std::abs(dx - predicted_dx) <= share_x * size.width && std::abs(dy) <= size.height / 20.0;
    }
    return count;
  };
  const Matcher& matcher = orb_override ? *match_matcher : *opened.matcher;
  while (const std::optional<Frame> next = source->Next()) {
    const Frame& frame = *next;
    const auto features = (orb_override ? *frame_matcher : *opened.matcher).Extract(frame.gray);
    const cv::Size size = features->image_size();
    for (int k = 0; k < num_keys; ++k) {
      const KeyComparison c = localizer.Compare(*features, k);
      const TentativeMatches m = matcher.Match(*features, *opened.keys.features[k]);
      const double predicted = previous_heading[k];
      heading[k] = c.heading.px;
      std::printf("%d,%d,%d,%d,%d,%d,%d,%.4f,%.3f,%d,%.4f,%d,%.2f,%d,%.2f,%d,%d", frame.index, frame.source_index, k,
                  c.matched ? 1 : 0, c.accepted ? 1 : 0, c.num_tentative, c.num_verified, c.similarity,
                  std::min(c.log10_nfa, 1e9), link_verified[k], c.heading.confidence, c.heading.votes, c.heading.px,
                  c.heading.num_voters, predicted, near(m, size, predicted, 1.0 / 80),
                  near(m, size, predicted, 1.0 / 40));
      if (guided) {
        const KeyComparison g = guided_localizer->Compare(*features, k);
        const TentativeMatches gm = guided_matcher->Match(*features, *opened.keys.features[k]);
        std::printf(",%d,%d,%.3f,%.2f,%d,%d,%d", g.num_tentative, g.num_verified, std::min(g.log10_nfa, 1e9),
                    g.heading.px, g.heading.votes, near(gm, size, predicted, 1.0 / 80),
                    near(gm, size, predicted, 1.0 / 40));
      }
      std::printf("\n");
    }
    previous_heading.swap(heading);
  }
  return 0;
}
