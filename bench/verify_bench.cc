// Speed of verifying one pair of XFeat matches, and whether the localizer's decision changes: today's verifiers
// and the bounded one, side by side on the same matches in one run (docs/matchers.md, "Speed of verification").
//
//   verify_bench [--set michigan|lab_floor|both] [--every N] [--top-k K] [--bounded SAMPLES:POINTS ...]
//
// michigan: ../shared/data/michigan_seasons, every pair of sessions at each place (330 pairs, 1024x384, the
// season changes between them: few, low-ratio verified matches). lab_floor: frames of lab_floor.mp4 paired with
// the frame 10, 30 and 60 later (thousands of matches, the tracking case). --every N keeps every N-th pair.
// Each pair is matched once (XFeat, its defaults) and verified by:
//   exhaustive  OpenCV's USAC_MAGSAC with the map's 100,000 iterations (what `vmap match` runs)
//   seed 1      the same with another seed: how many decisions a change of seed alone flips
//   localizer   the same capped at 5,000 iterations (what `vmap localize` ran before)
//   own         vmap's MAGSAC++ capped at 5,000, every match in the sample loop
//   S:P         vmap's MAGSAC++ with at most S samples on the P best-scored matches, refined on all (the
//               localizer's now: 1000:512; --bounded adds others)
// The decision is the localizer's default acceptance (at least 20 verified and S = verified / tentative >= 0.3).
// Times are the verifying thread's CPU time (the machine may be shared), and the pairs whose decision differs
// from the exhaustive run's are listed.

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "vmap/core/runtime.h"
#include "vmap/localization/localizer.h"
#include "vmap/mapping/key_image_selector.h"
#include "vmap/neural/xfeat/xfeat_matcher.h"
#include "vmap/sources/frame_source.h"

namespace fs = std::filesystem;

namespace {

struct Method {
  Method(std::string name, const vmap::VerifierOptions& options) : name(std::move(name)), options(options) {}
  std::string name;
  vmap::VerifierOptions options;
  std::vector<double> seconds;
  int accepted = 0, same_decision = 0;
  std::vector<int> verified_difference;  // |verified - exhaustive's| where both accept
};

double ThreadSeconds() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

double Percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  return values[std::min(values.size() - 1, static_cast<size_t>(p * values.size()))];
}

struct PairImages {
  std::string name;
  cv::Mat image0, image1;
};

std::vector<PairImages> MichiganPairs(int every) {
  const fs::path folder = fs::path(VMAP_SHARED_DIR) / "data/michigan_seasons/images";
  std::vector<PairImages> pairs;
  int index = 0;
  for (int place = 1; place <= 5; ++place) {
    for (int s0 = 1; s0 <= 12; ++s0) {
      for (int s1 = s0 + 1; s1 <= 12; ++s1) {
        if (index++ % every != 0) continue;
        char a[16], b[16];
        std::snprintf(a, sizeof a, "%02d%02d.png", s0, place);
        std::snprintf(b, sizeof b, "%02d%02d.png", s1, place);
        pairs.push_back({std::string(a) + "-" + b, cv::imread((folder / a).string(), cv::IMREAD_GRAYSCALE),
                         cv::imread((folder / b).string(), cv::IMREAD_GRAYSCALE)});
      }
    }
  }
  return pairs;
}

std::vector<PairImages> LabFloorPairs(int every) {
  vmap::FrameSourceOptions source;
  auto video = vmap::OpenFrameSource((fs::path(VMAP_SHARED_DIR) / "data/lab_floor/lab_floor.mp4").string(), source);
  std::vector<cv::Mat> frames;
  while (auto frame = video->Next()) frames.push_back(frame->gray.clone());
  std::vector<PairImages> pairs;
  int index = 0;
  for (size_t f = 0; f + 60 < frames.size(); f += 37) {
    for (int offset : {10, 30, 60}) {
      if (index++ % every != 0) continue;
      pairs.push_back({std::to_string(f) + "+" + std::to_string(offset), frames[f], frames[f + offset]});
    }
  }
  return pairs;
}

void Run(const std::string& set, const std::vector<PairImages>& pairs, const vmap::Matcher& matcher,
         const std::vector<std::pair<int, int>>& bounded_settings) {
  vmap::VerifierOptions exhaustive;  // the map's verifier: OpenCV's USAC_MAGSAC, 100,000 iterations
  vmap::VerifierOptions localizer = exhaustive;
  localizer.max_iterations = 5000;
  vmap::VerifierOptions own = localizer;
  own.own_magsac = true;
  vmap::VerifierOptions other_seed = exhaustive;  // the noise of the exhaustive run itself
  other_seed.seed = 1;
  std::vector<Method> methods = {
      {"exhaustive", exhaustive}, {"seed 1", other_seed}, {"localizer", localizer}, {"own", own}};
  for (const auto& [samples, points] : bounded_settings) {
    vmap::VerifierOptions bounded = localizer;  // as MapVerifierOptions makes it
    bounded.max_samples_to_reject = samples;
    bounded.loop_points = points;
    methods.emplace_back(std::to_string(samples) + ":" + std::to_string(points), bounded);
  }
  const vmap::LocalizerOptions acceptance;
  auto accepts = [&](const vmap::PairComparison& c) {
    return c.matched && c.num_verified >= acceptance.min_verified && c.similarity >= acceptance.min_similarity;
  };
  std::vector<double> tentative, extract_seconds, match_seconds;
  for (const PairImages& pair : pairs) {
    double start = ThreadSeconds();
    const auto f0 = matcher.Extract(pair.image0);
    extract_seconds.push_back(ThreadSeconds() - start);
    const auto f1 = matcher.Extract(pair.image1);
    start = ThreadSeconds();
    const vmap::TentativeMatches matches = matcher.Match(*f0, *f1);
    match_seconds.push_back(ThreadSeconds() - start);
    tentative.push_back(static_cast<double>(matches.size()));
    bool reference = false;
    int reference_verified = 0;
    for (Method& method : methods) {
      const double start = ThreadSeconds();
      const vmap::PairComparison c = vmap::VerifyMatches(matches, static_cast<int>(matches.size()), method.options);
      method.seconds.push_back(ThreadSeconds() - start);
      const bool accepted = accepts(c);
      if (&method != &methods.front() && accepted != reference) {
        std::printf("  %s %s: %s accepts %s (verified %d of %zu; exhaustive %d)\n", set.c_str(), pair.name.c_str(),
                    method.name.c_str(), accepted ? "yes" : "no", c.num_verified, matches.size(), reference_verified);
      }
      if (&method == &methods.front()) {
        reference = accepted;
        reference_verified = c.num_verified;
      }
      method.accepted += accepted;
      method.same_decision += accepted == reference;
      if (accepted && reference) method.verified_difference.push_back(std::abs(c.num_verified - reference_verified));
    }
  }
  std::printf("\n%s: %zu pairs, tentative matches median %.0f (min %.0f, max %.0f)\n", set.c_str(), pairs.size(),
              Percentile(tentative, 0.5), Percentile(tentative, 0.0), Percentile(tentative, 1.0));
  std::printf("XFeat CPU per image (extraction, one LibTorch thread) median %.1f ms; per pair (matching) %.1f ms\n",
              1e3 * Percentile(extract_seconds, 0.5), 1e3 * Percentile(match_seconds, 0.5));
  std::printf("%-11s %9s %9s %9s %9s %9s %9s %13s\n", "verifier", "cpu_med_ms", "p90_ms", "max_ms", "cpu_s", "accepted",
              "same", "|dv| median");
  for (const Method& m : methods) {
    double total = 0;
    for (double s : m.seconds) total += s;
    std::vector<double> dv(m.verified_difference.begin(), m.verified_difference.end());
    std::printf("%-11s %9.1f %9.1f %9.1f %9.2f %9d %5d/%-3zu %13.0f\n", m.name.c_str(),
                1e3 * Percentile(m.seconds, 0.5), 1e3 * Percentile(m.seconds, 0.9), 1e3 * Percentile(m.seconds, 1.0),
                total, m.accepted, m.same_decision, pairs.size(), Percentile(dv, 0.5));
  }
}

}  // namespace

int main(int argc, char** argv) {
  vmap::InitializeRuntime();  // the process set up as the vmap binary has it (core/runtime.h)
  std::string set = "both";
  int every = 1, top_k = 4096;
  std::vector<std::pair<int, int>> bounded = {{1000, 512}};
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&] { return i + 1 < argc ? std::string(argv[++i]) : std::string(); };
    if (arg == "--set") {
      set = value();
    } else if (arg == "--every") {
      every = std::max(1, std::stoi(value()));
    } else if (arg == "--top-k") {
      top_k = std::stoi(value());
    } else if (arg == "--bounded") {
      const std::string setting = value();
      const size_t colon = setting.find(':');
      if (colon == std::string::npos) return 2;
      bounded.emplace_back(std::stoi(setting.substr(0, colon)), std::stoi(setting.substr(colon + 1)));
    } else {
      std::fprintf(stderr,
                   "usage: verify_bench [--set michigan|lab_floor|both] [--every N] [--top-k K] "
                   "[--bounded SAMPLES:POINTS ...]\n");
      return 2;
    }
  }
  vmap::XfeatMatcherOptions options;
  options.weights = (fs::path(VMAP_SHARED_DIR) / "weights/xfeat/xfeat_folded.pt").string();
  options.top_k = top_k;
  const auto matcher = vmap::CreateXfeatMatcher(options);
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  std::printf("verify_bench: XFeat top_k %d, every %d-th pair; CPU time of the verifying thread\n", top_k, every);
  if (set == "michigan" || set == "both") Run("michigan_seasons", MichiganPairs(every), *matcher, bounded);
  if (set == "lab_floor" || set == "both") Run("lab_floor", LabFloorPairs(every), *matcher, bounded);
  return 0;
}
