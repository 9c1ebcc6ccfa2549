// Every frame of a query against every key image of a map, as the localizer compares them (Localizer::Compare):
// the evidence a belief over the route weighs, one CSV row per (frame, key image). The input of the calibration of
// the route belief's evidence (bench/route_conditions.py --evidence-dir, docs/localize.md).
//
//   evidence_dump MAP QUERY [--stride N] [--last N] [--cross-check 0|1] [--ratio R] [--frame-fast T]
//                 [--frame-features N] [--frame-edge PX] [--frame-grid-cell PX] [--frame-min-fast T] [--frame-clahe C]
//                 [--guided 1] [--windowed W[:Z[:D[:R[:L]]]][,...]] [--window-frame-fast T] [--window-frame-features N]
//
// Columns: frame, source_index, key, matched, accepted, tentative, verified, similarity, log10_nfa, link_verified
// (the smaller of the verified matches of the key image's links with its neighbours in the map; 0 without),
// heading_confidence, heading_votes, heading_px, heading_voters, and the continuity of the heading
// (docs/measurements/localization-conditions.md, "Continuity of the heading"): prev_heading_px, the previous frame's
// heading against the same key image (the prediction a tracking run has of this frame's; empty on the first frame or
// without a heading), and near_S / near_L, how many of this comparison's tentative matches move by the predicted
// displacement (dx within 1/80 or 1/40 of the image's width of prev_heading_px, dy within 1/20 of its height of 0).
// With --guided 1 (ORB maps), the same key image matched again as the localizer's guided matching does (no cross
// check): g_tentative, g_verified, g_log10_nfa, g_heading_px, g_heading_votes, g_near_S, g_near_L (g_near_* against the
// same prediction). With --windowed (ORB maps; docs/measurements/localization-conditions.md, "Matching guided by the
// prediction"), for each window given the frame matched with the key image by the prediction as the localizer's window
// matching does (MatchOrbInWindow: candidates within W of the image's width of prev_heading_px across and 1/20 of its
// height up or down, both widened by Z times the feature's distance from the image's centre, pyramid levels at most L
// apart, Hamming distance at most D, ratio R among the candidates; defaults Z 0, D 64, R 0.9, L 1) and verified as the
// localizer verifies: wN_tentative, wN_verified, wN_log10_nfa, wN_similarity for window N (-1, -1, 1e9, 0 without a
// prediction). The frame's features for it: the map's, or extracted again with FAST threshold T / N features (the
// localizer's window_fast_threshold, window_features). Last, rank and rank_score: the key image's place (0: the best)
// and score in the relocalization's ranking of every key image for the frame (KeyImageRanking, the map's options; a
// run compares the best-ranked key images, so its comparisons at wrong key images are not a random draw), and
// frame_features, the frame's number of features.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "vmap/core/runtime.h"
#include "vmap/features/matcher_registry.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/localization/acceptance.h"
#include "vmap/localization/key_image_ranking.h"
#include "vmap/localization/localization_map.h"
#include "vmap/mapping/key_image_selector.h"
#include "vmap/sources/frame_source.h"

using namespace vmap;

int Dump(int argc, char** argv) {
  // CLI11, as the vmap binary parses its flags: a flag it does not know, or one without its value, is an error.
  CLI::App app{"evidence_dump: every frame of a query against every key image of a map, one CSV row per pair"};
  std::string map_path, query_path, window_list;
  FrameSourceOptions query_options;
  // ORB only, an experiment (docs/localize.md, "guided matching"): the frame's features and the matching of the
  // comparisons made with other options than the map's (OrbMatcherOptions' defaults otherwise).
  OrbMatcherOptions frame_orb, match_orb;
  bool guided = false;
  int window_frame_fast = 0, window_frame_features = 0;
  double window_frame_clahe = 0.0;
  app.add_option("map", map_path, "the map directory")->required();
  app.add_option("query", query_path, "the query run (a video, an image folder, a TUM or KITTI sequence)")->required();
  app.add_option("--stride", query_options.stride, "every n-th frame of the query");
  app.add_option("--last", query_options.last, "the query's last frame");
  // The ORB experiment's options: any of them given, the comparisons use frame_orb / match_orb.
  const std::vector<CLI::Option*> orb_experiment = {
      app.add_option("--cross-check", match_orb.cross_check, "ORB matching with a cross check (0|1)"),
      app.add_option("--ratio", match_orb.ratio, "ORB matching's ratio test"),
      app.add_option("--frame-fast", frame_orb.fast_threshold, "the frame's FAST threshold"),
      app.add_option("--frame-features", frame_orb.num_features, "the frame's ORB features"),
      app.add_option("--frame-edge", frame_orb.edge_threshold, "the frame's ORB edge threshold (px)"),
      app.add_option("--frame-grid-cell", frame_orb.grid_cell, "the frame's ORB grid cell (px)"),
      app.add_option("--frame-min-fast", frame_orb.min_fast_threshold, "the frame's ORB fallback FAST threshold"),
      app.add_option("--frame-clahe", frame_orb.clahe_clip, "the frame's CLAHE clip limit")};
  app.add_option("--guided", guided, "also the guided comparison's columns (0|1)");
  app.add_option("--windowed", window_list, "windows for matching by the prediction: W[:Z[:D[:R[:L]]]][,...]");
  app.add_option("--window-frame-fast", window_frame_fast, "the window matching's frame FAST threshold");
  app.add_option("--window-frame-features", window_frame_features, "the window matching's frame features");
  app.add_option("--window-frame-clahe", window_frame_clahe, "the window matching's frame CLAHE clip limit");
  CLI11_PARSE(app, argc, argv);
  const bool orb_override =
      std::any_of(orb_experiment.begin(), orb_experiment.end(), [](const CLI::Option* o) { return o->count() > 0; });
  std::vector<std::vector<double>> windows;  // share of the width, zoom, max distance, ratio, level difference
  for (size_t at = 0; at < window_list.size();) {
    const size_t comma = std::min(window_list.find(',', at), window_list.size());
    const std::string spec = window_list.substr(at, comma - at);
    std::vector<double> values = {0.0625, 0.0, 64, 0.9, 1};
    size_t field = 0;
    for (size_t from = 0; from <= spec.size() && field < values.size(); ++field) {
      const size_t colon = std::min(spec.find(':', from), spec.size());
      values[field] = std::stod(spec.substr(from, colon - from));
      from = colon + 1;
    }
    windows.push_back(values);
    at = comma + 1;
  }
  InitializeRuntime();  // the process set up as the vmap binary has it (core/runtime.h)
  const LocalizationMap opened = OpenLocalizationMap(map_path, {});
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
  // The frame's features for the windowed matching: the map's ORB options, FAST threshold / features changed.
  std::unique_ptr<Matcher> window_frame_matcher;
  if (window_frame_fast > 0 || window_frame_features > 0 || window_frame_clahe > 0.0) {
    MatcherOptions o;
    o.type = OrbMatcherOptions::kModelName;
    o.model(o.type).FromJson(nlohmann::json::parse(opened.matcher->DescribeOptionsJson()), "the map's matcher");
    if (window_frame_fast > 0) o.Of<OrbMatcherOptions>().fast_threshold = window_frame_fast;
    if (window_frame_features > 0) o.Of<OrbMatcherOptions>().num_features = window_frame_features;
    o.Of<OrbMatcherOptions>().clahe_clip = window_frame_clahe;
    window_frame_matcher = CreateMatcher(o);
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
  // The relocalization's ranking of every key image, as the localizer ranks the route.
  const KeyImageRanking ranking(opened.keys.features, opened.keys.thumbnails, options.ranking);
  auto source = OpenFrameSource(query_path, query_options);
  std::printf(
      "frame,source_index,key,matched,accepted,tentative,verified,similarity,log10_nfa,link_verified,"
      "heading_confidence,heading_votes,heading_px,heading_voters,prev_heading_px,near_S,near_L%s%s",
      guided ? ",g_tentative,g_verified,g_log10_nfa,g_heading_px,g_heading_votes,g_near_S,g_near_L" : "", "");
  for (size_t w = 0; w < windows.size(); ++w) {
    std::printf(",w%zu_tentative,w%zu_verified,w%zu_log10_nfa,w%zu_similarity", w, w, w, w);
  }
  std::printf(",rank,rank_score,frame_features\n");
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
    // As the localizer extracts them (LocalizeSequence): XFeat and ALIKED read the frame's colour.
    const auto features = (orb_override ? *frame_matcher : *opened.matcher).ExtractFrame(frame.gray, frame.color);
    const cv::Size size = features->image_size();
    const auto window_features = window_frame_matcher ? window_frame_matcher->Extract(frame.gray) : features;
    const cv::Mat thumbnail = ranking.method() == RankingMethod::kThumbnails
                                  ? ThumbnailDescriptor(frame.gray, options.ranking.thumbnail_width)
                                  : cv::Mat();
    std::vector<int> rank_of(num_keys, -1);
    std::vector<double> score_of(num_keys, 0.0);
    const std::vector<RankedKey> ranked = ranking.Rank(*features, thumbnail);
    for (size_t i = 0; i < ranked.size(); ++i) {
      rank_of[ranked[i].key] = static_cast<int>(i);
      score_of[ranked[i].key] = ranked[i].score;
    }
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
      for (const std::vector<double>& spec : windows) {
        if (!std::isfinite(predicted)) {
          std::printf(",-1,-1,1e9,0");
          continue;
        }
        MatchWindow window;
        window.predicted_dx = predicted;
        window.half_width = spec[0] * size.width;
        window.half_height = size.height / 20.0;
        window.zoom = spec[1];
        window.max_distance = static_cast<int>(spec[2]);
        window.ratio = spec[3];
        window.max_level_difference = static_cast<int>(spec[4]);
        window.centre = cv::Point2f(size.width / 2.0f, size.height / 2.0f);
        const ImageFeatures& key_features = *opened.keys.features[k];
        const TentativeMatches wm = MatchOrbInWindow(*window_features, key_features, window);
        const PairComparison pair =
            VerifyMatches(wm,
                          SimilarityDenominator(options.similarity, static_cast<int>(wm.size()),
                                                window_features->num_features(), key_features.num_features()),
                          options.verifier);
        const double nfa =
            pair.matched ? ChanceOfComparison(pair, size, key_features.image_size(),
                                              ComparisonsPerFrame(options.lookahead, options.relocalization_candidates))
                               .log10_nfa
                         : 1e9;
        std::printf(",%d,%d,%.3f,%.4f", pair.num_tentative, pair.num_verified, std::min(nfa, 1e9), pair.similarity);
      }
      std::printf(",%d,%.4f,%d\n", rank_of[k], score_of[k], features->num_features());
    }
    previous_heading.swap(heading);
  }
  return 0;
}

// A map, a query or a plugin that cannot be opened is reported as the vmap binary reports it, not by std::terminate.
int main(int argc, char** argv) {
  try {
    return Dump(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "evidence_dump: error: %s\n", e.what());
    return 1;
  }
}
