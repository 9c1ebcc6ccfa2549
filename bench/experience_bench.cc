// Multi-experience maps across seasons (docs/experiences.md): a map of one michigan session (5 places, one key
// image each, in place order as the route) against the same map holding k other sessions as experiences, on
// the sessions held out of both, per place: the heading error rate (35 px criterion against gt.csv's labels,
// as heading_bench) and how many frames `vmap localize` puts at the right place.
//
//   experience_bench [--matchers orb,xfeat] [--teach 1,2,...,12] [--k 0,1,2,3] [--acceptance counts|chance]
//
// --acceptance: when a frame is seen at a key image, both while adding an experience and while localizing
// (LocalizerOptions::acceptance; counts by default, as vmap localize).
// For teach session t the experiences are the sessions spread over the year after it: k = 1: t+6; k = 2: t+4,
// t+8; k = 3: t+3, t+6, t+9 (mod 12). The queries are the six sessions in none of these sets (t+1, t+2, t+5,
// t+7, t+10, t+11), the same for every k, so that the columns compare like with like. An experience is added
// as `vmap build --add-experience-to` adds it (the session localized as a run of 5 frames against the map
// with the experiences added so far; ExperienceViewPicker). Heading: Localizer::Compare of the query image with
// the key image of its place (the key image and its views, the best fitting), against the label teach -> query.
// Localization: the query session's 5 images localized in order as one run from scratch; right when the frame
// is localized (not lost) with `key` the key image of its place.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "vmap/core/runtime.h"
#include "vmap/evaluation/heading_labels.h"
#include "vmap/features/matcher_registry.h"
#include "vmap/localization/add_experience.h"
#include "vmap/localization/key_image_ranking.h"
#include "vmap/localization/localizer.h"
#include "vmap/mapping/key_image_selector.h"

#include "cpu_time.h"

using namespace vmap;

namespace {

constexpr double kCorrectPx = 35.0;
constexpr int kSessions = 12;
constexpr int kPlaces = 5;
const std::string kData = std::string(VMAP_SHARED_DIR) + "/data/michigan_seasons";

std::string ImageName(int session, int place) {
  char name[32];
  std::snprintf(name, sizeof(name), "images/%02d%02d.png", session, place);
  return name;
}

// label[place][teach][query] = x_query - x_teach (gt.csv holds teach < query; the other way is its negation).
using Labels = std::map<std::pair<std::string, std::string>, double>;

Labels LoadLabels() {
  Labels labels;
  for (const HeadingLabel& l : ReadHeadingLabels(kData + "/gt.csv")) {
    labels[{l.teach_image, l.repeat_image}] = l.dx_px;
    labels[{l.repeat_image, l.teach_image}] = -l.dx_px;
  }
  return labels;
}

std::vector<int> ParseList(const std::string& text) {
  std::vector<int> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) values.push_back(std::stoi(item));
  return values;
}

int Session(int session) { return (session - 1 + kSessions) % kSessions + 1; }

std::vector<int> ExperienceSessions(int teach, int k) {
  std::vector<int> sessions;
  for (int j = 1; j <= k; ++j) sessions.push_back(Session(teach + j * kSessions / (k + 1)));
  return sessions;
}

struct Images {
  std::vector<std::vector<cv::Mat>> gray;  // [session][place], 1-based
  std::vector<std::vector<std::shared_ptr<const ImageFeatures>>> features;
  double extract_ms = 0.0;
};

Images Extract(const Matcher& matcher) {
  Images images;
  images.gray.assign(kSessions + 1, std::vector<cv::Mat>(kPlaces + 1));
  images.features.assign(kSessions + 1, std::vector<std::shared_ptr<const ImageFeatures>>(kPlaces + 1));
  const double start = vmap::bench::ProcessCpuSeconds();
  for (int s = 1; s <= kSessions; ++s) {
    for (int p = 1; p <= kPlaces; ++p) {
      cv::Mat gray = cv::imread(kData + "/" + ImageName(s, p), cv::IMREAD_GRAYSCALE);
      if (gray.empty()) throw std::runtime_error("cannot read " + kData + "/" + ImageName(s, p));
      images.features[s][p] = matcher.ExtractFrame(gray, cv::Mat());
      images.gray[s][p] = gray;
    }
  }
  images.extract_ms = 1e3 * (vmap::bench::ProcessCpuSeconds() - start) / (kSessions * kPlaces);
  return images;
}

// The map vmap build makes of one session: every image a key image (the places share nothing), linked in
// order. Built here from the features extracted once, as the builder links consecutive key images.
VisualMap TeachMap(const Images& images, int teach, const Matcher& matcher, const LocalizerOptions& options) {
  VisualMap map;
  map.num_frames = kPlaces;
  map.input.frame_size = images.gray[teach][1].size();
  for (int p = 1; p <= kPlaces; ++p) {
    KeyImage key;
    key.frame_index = key.source_index = p - 1;
    key.source_name = ImageName(teach, p);
    map.key_images.push_back(key);
    if (p > 1) {
      const PairComparison pair = ComparePair(matcher, *images.features[teach][p - 1], *images.features[teach][p],
                                              options.verifier, options.similarity);
      map.links.push_back(MakeLink(pair, p - 2, p - 1, /*below_tau=*/true));
    }
  }
  return map;
}

Frame MakeFrame(const Images& images, int session, int place) {
  Frame frame;
  frame.index = frame.source_index = place - 1;
  frame.source_name = ImageName(session, place);
  frame.gray = images.gray[session][place];
  return frame;
}

struct Tally {
  int pairs[kPlaces + 1] = {};
  int heading_wrong[kPlaces + 1] = {};
  int localized_right[kPlaces + 1] = {};
  int localized_wrong[kPlaces + 1] = {};
  std::vector<double> errors;
  int used_experience = 0;  // headings taken from a view
  double compare_seconds = 0.0;
  int compares = 0;
};

void Run(const std::string& name, const Matcher& matcher, const std::vector<int>& teach_sessions,
         const std::vector<int>& ks, const Labels& labels, AcceptanceRule acceptance) {
  const Images images = Extract(matcher);
  LocalizerOptions options;
  options.acceptance = acceptance;
  options.Check();
  std::map<int, Tally> tallies;
  for (int teach : teach_sessions) {
    std::fprintf(stderr, "%s: teach session %d\n", name.c_str(), teach);
    const VisualMap map = TeachMap(images, teach, matcher, options);
    std::vector<int> queries;
    const std::vector<int> excluded = {0, 3, 4, 6, 8, 9};  // teach and every experience of k <= 3
    for (int d = 1; d < kSessions; ++d) {
      if (std::find(excluded.begin(), excluded.end(), d) == excluded.end()) queries.push_back(Session(teach + d));
    }
    for (int k : ks) {
      KeyImageStore store;
      for (int p = 1; p <= kPlaces; ++p) {
        store.features.push_back(images.features[teach][p]);
        store.thumbnails.push_back(ThumbnailDescriptor(images.gray[teach][p], options.ranking.thumbnail_width));
      }
      int id = 0;
      for (int session : ExperienceSessions(teach, k)) {
        // As AddExperience: the session localized as a run against the map with the experiences so far.
        Localizer localizer(map, store, matcher, options);
        ExperienceViewPicker picker(kPlaces);
        for (int p = 1; p <= kPlaces; ++p)
          picker.Offer(localizer.Localize(MakeFrame(images, session, p), *images.features[session][p]));
        ++id;
        if (store.views.empty()) store.views.resize(kPlaces);
        for (const ExperienceView& v : picker.Views()) {
          store.views[v.key].push_back({id, v.heading_px, images.features[session][v.key + 1]});
        }
      }
      Tally& tally = tallies[k];
      Localizer localizer(map, store, matcher, options);
      for (int query : queries) {
        localizer.Reset();
        for (int p = 1; p <= kPlaces; ++p) {
          const LocalizationResult r = localizer.Localize(MakeFrame(images, query, p), *images.features[query][p]);
          const bool localized = r.status != LocalizationStatus::kLost && r.key >= 0;
          tally.localized_right[p] += localized && r.key == p - 1;
          tally.localized_wrong[p] += localized && r.key != p - 1;
          const double start = vmap::bench::ProcessCpuSeconds();
          const KeyComparison c = localizer.Compare(*images.features[query][p], p - 1);
          tally.compare_seconds += vmap::bench::ProcessCpuSeconds() - start;
          ++tally.compares;
          const double label = labels.at({ImageName(teach, p), ImageName(query, p)});
          const double error = std::isfinite(c.heading.px) ? std::abs(c.heading.px - label) : 1e9;
          tally.errors.push_back(error);
          tally.heading_wrong[p] += error > kCorrectPx;
          tally.used_experience += c.experience > 0;
          ++tally.pairs[p];
        }
      }
    }
  }
  std::printf("\n%s, --acceptance %s, teach sessions %zu (extraction %.0f ms/image)\n", name.c_str(),
              AcceptanceRuleName(acceptance).c_str(), teach_sessions.size(), images.extract_ms);
  std::printf(
      "| matcher | experiences k | pairs | heading error rate pl1..pl5 (%%) | heading error rate | median error "
      "| right place pl1..pl5 (%%) | right place | wrong place | heading from a view | ms/compare |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (int k : ks) {
    Tally& t = tallies[k];
    std::string per_place_heading, per_place_right;
    int pairs = 0, wrong = 0, right = 0, misplaced = 0;
    for (int p = 1; p <= kPlaces; ++p) {
      char cell[32];
      std::snprintf(cell, sizeof(cell), "%s%.1f", p > 1 ? " / " : "", 100.0 * t.heading_wrong[p] / t.pairs[p]);
      per_place_heading += cell;
      std::snprintf(cell, sizeof(cell), "%s%.1f", p > 1 ? " / " : "", 100.0 * t.localized_right[p] / t.pairs[p]);
      per_place_right += cell;
      pairs += t.pairs[p];
      wrong += t.heading_wrong[p];
      right += t.localized_right[p];
      misplaced += t.localized_wrong[p];
    }
    std::nth_element(t.errors.begin(), t.errors.begin() + t.errors.size() / 2, t.errors.end());
    std::printf("| %s | %d | %d | %s | %.1f %% | %.1f px | %s | %.1f %% | %.1f %% | %.1f %% | %.1f |\n", name.c_str(),
                k, pairs, per_place_heading.c_str(), 100.0 * wrong / pairs, t.errors[t.errors.size() / 2],
                per_place_right.c_str(), 100.0 * right / pairs, 100.0 * misplaced / pairs,
                100.0 * t.used_experience / pairs, 1e3 * t.compare_seconds / t.compares);
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  vmap::InitializeRuntime();  // the process set up as the vmap binary has it (core/runtime.h)
  std::string matchers = "orb,xfeat";
  std::vector<int> teach = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  std::vector<int> ks = {0, 1, 2, 3};
  AcceptanceRule acceptance = AcceptanceRule::kCounts;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--matchers" && i + 1 < argc) {
      matchers = argv[++i];
    } else if (arg == "--teach" && i + 1 < argc) {
      teach = ParseList(argv[++i]);
    } else if (arg == "--k" && i + 1 < argc) {
      ks = ParseList(argv[++i]);
    } else if (arg == "--acceptance" && i + 1 < argc) {
      acceptance = ParseAcceptanceRule(argv[++i]);
    } else {
      std::fprintf(stderr,
                   "usage: experience_bench [--matchers orb,xfeat] [--teach 1,...,12] [--k 0,1,2,3] "
                   "[--acceptance counts|chance]\n");
      return 2;
    }
  }
  for (int k : ks) {
    if (k < 0 || k > 3) {
      std::fprintf(stderr, "experience_bench: --k values must be 0 to 3 (the held-out queries assume it)\n");
      return 2;
    }
  }
  const Labels labels = LoadLabels();
  for (const std::string& type : {std::string("orb"), std::string("xfeat")}) {
    if (matchers.find(type) == std::string::npos) continue;
    try {
      MatcherOptions options;
      options.type = type;
      const std::unique_ptr<Matcher> matcher = CreateMatcher(options);
      Run(type, *matcher, teach, ks, labels, acceptance);
    } catch (const std::exception& e) {
      std::printf("%s: not measured (%s)\n", type.c_str(), e.what());
    }
  }
  return 0;
}
