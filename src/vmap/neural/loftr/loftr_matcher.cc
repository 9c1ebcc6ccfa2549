#include "vmap/neural/loftr/loftr_matcher.h"

#include <cmath>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "vmap/core/error.h"
#include "vmap/core/file_name_encoding.h"
#include "vmap/features/matcher_plugin.h"
#include "vmap/neural/loftr/loftr_model.h"
#include "vmap/neural/loftr/loftr_weights.h"
#include "vmap/neural/torch_device.h"
#include "vmap/neural/weights_store.h"

namespace vmap {

namespace {

using neural::LoftrConfig;
using neural::LoftrModel;

class LoftrFeatures : public ImageFeatures {
 public:
  LoftrFeatures(neural::LoftrImageFeatures net, cv::Size original) : net_(std::move(net)), original_(original) {}
  // Every coarse cell is a candidate: LoFTR has no detector.
  int num_features() const override { return static_cast<int>(net_.coarse_h * net_.coarse_w); }
  cv::Size image_size() const override { return original_; }
  const neural::LoftrImageFeatures& net() const { return net_; }

 private:
  neural::LoftrImageFeatures net_;
  cv::Size original_;
};

class LoftrMatcher : public Matcher {
 public:
  LoftrMatcher(const LoftrMatcherOptions& options, LoftrConfig config, const neural::StateDict& weights,
               std::string weights_path)
      : options_(options),
        weights_path_(std::move(weights_path)),
        model_(std::move(config), weights, neural::ParseTorchDevice(options.device)) {}

  std::string name() const override { return "loftr"; }

  std::shared_ptr<const ImageFeatures> Extract(const cv::Mat& gray) const override {
    if (gray.empty() || gray.type() != CV_8UC1) {
      throw InputError("LoFTR needs an 8-bit single-channel image");
    }
    const cv::Size net_size = NetworkSize(gray.size());
    cv::Mat resized = gray;
    if (net_size != gray.size()) {
      // INTER_AREA when shrinking, as the reference's preprocessing does for large frames.
      const bool shrinking = net_size.area() < gray.size().area();
      cv::resize(gray, resized, net_size, 0, 0, shrinking ? cv::INTER_AREA : cv::INTER_LINEAR);
    }
    if (!resized.isContinuous()) resized = resized.clone();
    UseThreads();
    torch::InferenceMode guard;
    // uint8 -> float then / 255 (not * (1/255)): bit-identical to the reference input.
    auto image = torch::from_blob(resized.data, {1, 1, resized.rows, resized.cols}, torch::kUInt8)
                     .to(torch::kFloat32)
                     .div_(255.0);
    return std::make_shared<LoftrFeatures>(model_.Extract(image), gray.size());
  }

  TentativeMatches Match(const ImageFeatures& features0, const ImageFeatures& features1) const override {
    const auto* f0 = dynamic_cast<const LoftrFeatures*>(&features0);
    const auto* f1 = dynamic_cast<const LoftrFeatures*>(&features1);
    if (!f0 || !f1) throw std::invalid_argument("LoftrMatcher::Match: features from another matcher");
    UseThreads();
    torch::InferenceMode guard;
    const auto out = model_.Match(f0->net(), f1->net());
    const bool fine = model_.config().has_fine;
    auto points0 = (fine ? out.mkpts0_f : out.mkpts0_c).to(torch::kCPU).contiguous();
    auto points1 = (fine ? out.mkpts1_f : out.mkpts1_c).to(torch::kCPU).contiguous();
    auto scores = out.mconf.to(torch::kCPU).contiguous();
    TentativeMatches matches;
    const int64_t n = points0.size(0);
    matches.points0.reserve(n);
    matches.points1.reserve(n);
    matches.scores.reserve(n);
    const float* p0 = points0.data_ptr<float>();
    const float* p1 = points1.data_ptr<float>();
    const float* s = scores.data_ptr<float>();
    const auto sx0 = float(f0->image_size().width) / float(f0->net().width);
    const auto sy0 = float(f0->image_size().height) / float(f0->net().height);
    const auto sx1 = float(f1->image_size().width) / float(f1->net().width);
    const auto sy1 = float(f1->image_size().height) / float(f1->net().height);
    for (int64_t k = 0; k < n; ++k) {
      matches.points0.emplace_back(p0[2 * k] * sx0, p0[2 * k + 1] * sy0);
      matches.points1.emplace_back(p1[2 * k] * sx1, p1[2 * k + 1] * sy1);
      matches.scores.push_back(s[k]);
    }
    return matches;
  }

  std::string DescribeOptionsJson() const override {
    const auto& c = model_.config();
    nlohmann::json j{{"type", "loftr"},
                     {"model", c.preset},
                     {"weights", EncodeFileName(weights_path_)},  // JSON needs UTF-8: see file_name_encoding.h
                     {"device", options_.device},
                     {"longest_side", options_.longest_side},
                     {"threshold", model_.threshold()},
                     {"border_removal", c.border_removal},
                     {"coarse_stride", c.coarse_stride},
                     {"fine_level", c.has_fine},
                     {"temp_bug_fix", c.temp_bug_fix}};
    return j.dump();
  }

 private:
  // OpenMP thread counts belong to the calling thread, so they are set on every call, not once.
  void UseThreads() const {
    if (options_.num_threads > 0 && at::get_num_threads() != options_.num_threads) {
      at::set_num_threads(options_.num_threads);
    }
  }

  // Longest side scaled to options_.longest_side, both sides rounded to whole coarse cells.
  cv::Size NetworkSize(cv::Size original) const {
    const int stride = model_.config().coarse_stride;
    if (original.width < stride || original.height < stride) {
      throw InputError("image of " + std::to_string(original.width) + "x" + std::to_string(original.height) +
                       " is smaller than one LoFTR coarse cell (" + std::to_string(stride) + " px)");
    }
    const double scale = double(options_.longest_side) / double(std::max(original.width, original.height));
    const int width = static_cast<int>(std::lround(original.width * scale / stride)) * stride;
    const int height = static_cast<int>(std::lround(original.height * scale / stride)) * stride;
    if (width < stride || height < stride) {
      // Found while matching, outside any check of the options: named as MatcherOptions holds them.
      throw OptionError(std::string(LoftrMatcherOptions::kModelName) + ".longest_side",
                        std::to_string(options_.longest_side) +
                            " gives less than one LoFTR coarse cell for an image "
                            "of " +
                            std::to_string(original.width) + "x" + std::to_string(original.height) +
                            "; raise it or crop the image");
    }
    return {width, height};
  }

  LoftrMatcherOptions options_;
  std::string weights_path_;
  LoftrModel model_;
};

}  // namespace

std::unique_ptr<Matcher> CreateLoftrMatcher(const LoftrMatcherOptions& options) {
  options.Check();
  LoftrConfig config = neural::LoftrPreset(options.model);
  if (options.threshold >= 0) config.threshold = options.threshold;
  const std::string path = neural::LocateWeights(options.model, options.weights);
  const auto weights = neural::ReadStateDict(path);
  neural::CheckStateDict(weights, config, path);
  return std::make_unique<LoftrMatcher>(options, std::move(config), weights, path);
}

}  // namespace vmap

namespace vmap {

std::vector<std::string> LoftrPresetsFittingFile(const std::string& path) {
  return neural::MatchingPresets(neural::ReadStateDict(path));
}

namespace {
// LoFTR's row in the plugin's table (features/matcher_plugin.h).
const PluginMatcherRegistration kLoftrPlugin{PluginMatcherModel{
    LoftrMatcherOptions::kModelName,
    [](const ModelOptions& options) { return CreateLoftrMatcher(options.As<LoftrMatcherOptions>()); },
    &LoftrPresetsFittingFile}};
}  // namespace

}  // namespace vmap
