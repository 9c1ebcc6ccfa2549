// Heading across seasons (docs/seasons.md): the error rate of vmap's heading estimate on the michigan
// seasonal pairs (../shared/data/michigan_seasons, 330 hand-labelled pairs of 5 places), per place and
// overall, for each matcher and estimator tried, with the median error and the CPU time of one pair.
//
//   heading_bench [--matchers orb,xfeat] [--sweep] [--verified]
//
// A heading is correct within 35 px of the label (the criterion of Krajnik et al., RAS 2017); the error rate
// is the share of incorrect ones (a pair without an estimate is incorrect). The teach image is the first of
// the pair, the repeat image the second, as `vmap match TEACH REPEAT`: the heading is x_repeat - x_teach,
// which gt.csv holds.
//
// Without --sweep: the chosen defaults (ORB as vmap's default matcher, and XFeat), the mode alone and with the
// F-verified median where F keeps many matches (what vmap match and localize report). --sweep adds the options
// tried (more ORB features, the ratio test instead of cross-checking, upright ORB, ORB on a CLAHE-equalised
// image, window widths and heights; 0 = displacements vote by x alone); --verified adds the median displacement of
// the F-verified matches (what vmap localize reported before) and other thresholds of the combination.
// ms/pair: CPU time (this process, all threads) of extracting both images, matching and estimating, from
// the per-image and per-pair means. Run from anywhere: XFeat's plugin is linked beside the binary.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "vmap/core/numeric.h"
#include "vmap/core/runtime.h"
#include "vmap/evaluation/heading_labels.h"
#include "vmap/features/matcher_registry.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/geometry/fundamental.h"
#include "vmap/geometry/heading.h"
#include "vmap/geometry/relative_pose.h"
#include "vmap/neural/xfeat/xfeat_options.h"

#include "cpu_time.h"

using namespace vmap;

namespace {

constexpr double kCorrectPx = 35.0;
const std::string kData = std::string(VMAP_SHARED_DIR) + "/data/michigan_seasons";

struct LabelledPair {
  int teach, repeat;  // image indices
  int place;          // 1..5
  double dx;          // x_repeat - x_teach
};

struct Dataset {
  std::vector<std::string> names;
  std::vector<cv::Mat> images;
  std::vector<LabelledPair> pairs;
};

Dataset LoadMichigan() {
  Dataset data;
  std::map<std::string, int> index;
  auto image = [&](const std::string& name) {
    auto it = index.find(name);
    if (it != index.end()) return it->second;
    cv::Mat gray = cv::imread(kData + "/" + name, cv::IMREAD_GRAYSCALE);
    if (gray.empty()) throw std::runtime_error("cannot read " + kData + "/" + name);
    data.names.push_back(name);
    data.images.push_back(gray);
    return index[name] = static_cast<int>(data.images.size()) - 1;
  };
  for (const HeadingLabel& label : ReadHeadingLabels(kData + "/gt.csv")) {
    LabelledPair pair;
    pair.teach = image(label.teach_image);
    pair.repeat = image(label.repeat_image);
    pair.place = std::stoi(label.teach_image.substr(label.teach_image.size() - 6, 2));  // images/SSLL.png
    pair.dx = label.dx_px;
    data.pairs.push_back(pair);
  }
  return data;
}

// Tentative matches of every labelled pair, made once per matcher configuration, with their cost.
struct MatchedSet {
  std::string name;
  std::vector<TentativeMatches> matches;  // per pair, teach -> repeat
  double extract_ms = 0.0;                // per image
  double match_ms = 0.0;                  // per pair
  double mean_tentative = 0.0;
};

using ExtractFn = std::function<std::shared_ptr<const ImageFeatures>(const cv::Mat&)>;
using MatchFn = std::function<TentativeMatches(const ImageFeatures&, const ImageFeatures&)>;

MatchedSet MatchAll(const std::string& name, const Dataset& data, const ExtractFn& extract, const MatchFn& match) {
  MatchedSet set;
  set.name = name;
  std::vector<std::shared_ptr<const ImageFeatures>> features;
  double start = vmap::bench::ProcessCpuSeconds();
  for (const cv::Mat& image : data.images) features.push_back(extract(image));
  set.extract_ms = 1e3 * (vmap::bench::ProcessCpuSeconds() - start) / data.images.size();
  start = vmap::bench::ProcessCpuSeconds();
  for (const LabelledPair& pair : data.pairs)
    set.matches.push_back(match(*features[pair.teach], *features[pair.repeat]));
  set.match_ms = 1e3 * (vmap::bench::ProcessCpuSeconds() - start) / data.pairs.size();
  for (const TentativeMatches& m : set.matches) set.mean_tentative += double(m.size()) / set.matches.size();
  return set;
}

// ORB as vmap's matcher computes it, optionally upright (every keypoint's angle set to 0 before the
// descriptors: the robot's camera does not roll) and on a CLAHE-equalised image.
struct OrbVariant {
  int num_features = 500;
  bool cross_check = true;
  double ratio = 0.0;
  bool upright = false;
  bool clahe = false;
};

class BenchOrbFeatures : public ImageFeatures {
 public:
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat binary;
  cv::Size size;
  int num_features() const override { return static_cast<int>(keypoints.size()); }
  cv::Size image_size() const override { return size; }
  cv::Mat descriptors() const override { return binary; }
};

MatchedSet MatchOrb(const std::string& name, const Dataset& data, const OrbVariant& v) {
  const OrbMatcherOptions defaults;
  auto extract = [&](const cv::Mat& gray) -> std::shared_ptr<const ImageFeatures> {
    cv::Mat input = gray;
    if (v.clahe) cv::createCLAHE(2.0, cv::Size(8, 8))->apply(gray, input);
    cv::Ptr<cv::ORB> orb =
        cv::ORB::create(v.num_features, static_cast<float>(defaults.scale_factor), defaults.num_levels,
                        defaults.edge_threshold, 0, 2, cv::ORB::HARRIS_SCORE, 31, defaults.fast_threshold);
    auto f = std::make_shared<BenchOrbFeatures>();
    f->size = gray.size();
    if (v.upright) {
      orb->detect(input, f->keypoints);
      for (cv::KeyPoint& k : f->keypoints) k.angle = 0.0f;
      orb->compute(input, f->keypoints, f->binary);
    } else {
      orb->detectAndCompute(input, cv::noArray(), f->keypoints, f->binary);
    }
    return f;
  };
  auto match = [&](const ImageFeatures& a0, const ImageFeatures& b0) {
    const auto& a = static_cast<const BenchOrbFeatures&>(a0);
    const auto& b = static_cast<const BenchOrbFeatures&>(b0);
    TentativeMatches m;
    if (a.binary.empty() || b.binary.empty()) return m;
    for (const auto& [i, j] : MatchBinaryDescriptors(a.binary, b.binary, v.cross_check, v.ratio)) {
      m.points0.push_back(a.keypoints[i].pt);
      m.points1.push_back(b.keypoints[j].pt);
    }
    return m;
  };
  return MatchAll(name, data, extract, match);
}

MatchedSet MatchWithMatcher(const std::string& name, const Dataset& data, const Matcher& matcher) {
  return MatchAll(
      name, data, [&](const cv::Mat& gray) { return matcher.Extract(gray); },
      [&](const ImageFeatures& a, const ImageFeatures& b) { return matcher.Match(a, b); });
}

// One way of turning a pair's tentative matches into a heading.
struct Estimator {
  std::string name;
  std::function<double(const TentativeMatches&)> heading;  // NaN: no estimate
};

Estimator ModeEstimator(const HeadingOptions& options) {
  char name[64];
  std::snprintf(name, sizeof(name), "mode %g x %s", options.window_px,
                options.window_dy_px > 0 ? std::to_string(int(options.window_dy_px)).c_str() : "any dy");
  return {name, [options](const TentativeMatches& m) { return EstimateHeading(m.points0, m.points1, options).px; }};
}

// The median displacement of the matches F verifies (0.5 px MAGSAC++, vmap's defaults, iterations capped as
// vmap localize caps them); with `min_verified` > 0, vmap's heading where F is estimated: that median when F
// keeps at least `min_verified` matches, else the mode (EstimateHeading with the inlier mask).
Estimator VerifiedEstimator(int min_verified) {
  VerifierOptions verifier;
  verifier.max_iterations = 5000;
  HeadingOptions options;
  options.min_verified = min_verified;
  std::string name =
      min_verified > 0 ? "F>=" + std::to_string(min_verified) + " ? verified : mode" : std::string("verified median");
  return {name, [=](const TentativeMatches& m) {
            FundamentalResult f;
            if (static_cast<int>(m.size()) >= verifier.min_matches)
              f = EstimateFundamental(m.points0, m.points1, verifier);
            if (min_verified > 0) return EstimateHeading(m.points0, m.points1, f.inlier_mask, options).px;
            std::vector<double> dx;
            for (size_t i = 0; i < f.inlier_mask.size(); ++i) {
              if (f.inlier_mask[i]) dx.push_back(m.points1[i].x - m.points0[i].x);
            }
            return dx.empty() ? std::nan("") : Median(dx);
          }};
}

void Report(const Dataset& data, const MatchedSet& set, const Estimator& estimator) {
  int wrong[6] = {0}, total[6] = {0};
  std::vector<double> errors;
  const double start = vmap::bench::ProcessCpuSeconds();
  for (size_t p = 0; p < data.pairs.size(); ++p) {
    const LabelledPair& pair = data.pairs[p];
    const double heading = estimator.heading(set.matches[p]);
    const double error = std::isfinite(heading) ? std::abs(heading - pair.dx) : 1e9;
    errors.push_back(error);
    ++total[pair.place];
    ++total[0];
    if (!(error <= kCorrectPx)) {
      ++wrong[pair.place];
      ++wrong[0];
    }
  }
  const double estimate_ms = 1e3 * (vmap::bench::ProcessCpuSeconds() - start) / data.pairs.size();
  std::sort(errors.begin(), errors.end());
  const double median = errors[errors.size() / 2];
  std::printf("%-22s %-24s", set.name.c_str(), estimator.name.c_str());
  for (int place = 1; place <= 5; ++place)
    std::printf(" %6.1f", total[place] ? 100.0 * wrong[place] / total[place] : 0.0);
  std::printf(" %7.1f %8.1f %8.1f %8.1f %6.0f\n", 100.0 * wrong[0] / total[0], median,
              2 * set.extract_ms + set.match_ms + estimate_ms, estimate_ms, set.mean_tentative);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  vmap::InitializeRuntime();  // the process set up as the vmap binary has it (core/runtime.h)
  std::string matchers = "orb,xfeat";
  bool sweep = false, verified = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--matchers" && i + 1 < argc)
      matchers = argv[++i];
    else if (arg == "--sweep")
      sweep = true;
    else if (arg == "--verified")
      verified = true;
    else {
      std::fprintf(stderr, "usage: heading_bench [--matchers orb,xfeat] [--sweep] [--verified]\n");
      return 2;
    }
  }
  const Dataset data = LoadMichigan();
  std::printf(
      "michigan_seasons: %zu images, %zu labelled pairs; error rate (%%) = share of headings more than %g px "
      "off\nanchors (Krajnik et al. RAS 2017, michigan): 1.5%% best (STAR/GRIEF), 20.9%% ORB/ORB\n\n",
      data.images.size(), data.pairs.size(), kCorrectPx);
  std::printf("%-22s %-24s %6s %6s %6s %6s %6s %7s %8s %8s %8s %6s\n", "matcher", "estimator", "pl1", "pl2", "pl3",
              "pl4", "pl5", "err%", "med_px", "ms/pair", "est_ms", "tent");
  const HeadingOptions chosen;
  // The mode alone (what a pair without F gets), and vmap's heading where F is estimated (match, localize).
  std::vector<Estimator> estimators = {ModeEstimator(chosen), VerifiedEstimator(chosen.min_verified)};
  if (sweep) {
    for (double wdy : {0.0, 10.0, 20.0, 40.0, 80.0}) {
      for (double w : {10.0, 20.0, 35.0}) {
        if (w == chosen.window_px && wdy == chosen.window_dy_px) continue;
        HeadingOptions o;
        o.window_px = w;
        o.window_dy_px = wdy;
        estimators.push_back(ModeEstimator(o));
      }
    }
  }
  if (verified) {
    estimators.push_back(VerifiedEstimator(0));
    estimators.push_back(VerifiedEstimator(20));
    estimators.push_back(VerifiedEstimator(100));
  }
  auto run = [&](const MatchedSet& set, bool all) {
    if (all) {
      for (const Estimator& e : estimators) Report(data, set, e);
    } else {
      Report(data, set, estimators[0]);
    }
  };

  if (matchers.find("orb") != std::string::npos) {
    run(MatchOrb("orb (vmap default)", data, OrbVariant{}), true);
    if (sweep) {
      for (int n : {1000, 1600, 3000}) {
        OrbVariant v;
        v.num_features = n;
        run(MatchOrb("orb " + std::to_string(n), data, v), n == 3000);
      }
      OrbVariant ratio;
      ratio.num_features = 1600;
      ratio.cross_check = false;
      ratio.ratio = 0.8;
      run(MatchOrb("orb 1600 ratio 0.8", data, ratio), false);
      OrbVariant upright;
      upright.upright = true;
      run(MatchOrb("orb upright", data, upright), false);
      upright.num_features = 1600;
      run(MatchOrb("orb 1600 upright", data, upright), false);
      OrbVariant clahe;
      clahe.clahe = true;
      run(MatchOrb("orb clahe", data, clahe), false);
      clahe.num_features = 1600;
      run(MatchOrb("orb 1600 clahe", data, clahe), false);
      clahe.upright = true;
      run(MatchOrb("orb 1600 upright clahe", data, clahe), false);
      clahe.num_features = 3000;
      run(MatchOrb("orb 3000 upright clahe", data, clahe), false);
    }
  }
  if (matchers.find("xfeat") != std::string::npos) {
    try {
      MatcherOptions options;
      options.type = "xfeat";
      const std::unique_ptr<Matcher> matcher = CreateMatcher(options);
      run(MatchWithMatcher("xfeat", data, *matcher), true);
      if (sweep) {
        options.Of<XfeatMatcherOptions>().top_k = 2048;
        run(MatchWithMatcher("xfeat top_k 2048", data, *CreateMatcher(options)), false);
      }
    } catch (const std::exception& e) {
      std::printf("xfeat: not measured (%s)\n", e.what());
    }
  }
  return 0;
}
