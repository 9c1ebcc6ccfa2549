#include "vmap/neural/xfeat/xfeat_matcher.h"

#include <cmath>
#include <limits>

#include <nlohmann/json.hpp>

#include "vmap/core/error.h"
#include "vmap/core/file_name_encoding.h"
#include "vmap/features/float_matcher.h"
#include "vmap/features/matcher_plugin.h"
#include "vmap/features/point_features_bytes.h"
#include "vmap/neural/torch_device.h"
#include "vmap/neural/weights_store.h"
#include "vmap/neural/xfeat/xfeat_model.h"
#include "vmap/neural/xfeat/xfeat_weights.h"

namespace vmap {

namespace {

constexpr int kMinimumSide = 32;                       // the network input is the image cut down to multiples of 32
constexpr std::string_view kFeaturesTag = "vmapXFT1";  // the localization cache's record of XFeat features

class XfeatFeatures : public ImageFeatures {
 public:
  XfeatFeatures(std::vector<cv::Point2f> keypoints, torch::Tensor descriptors, cv::Size image_size)
      : keypoints_(std::move(keypoints)), descriptors_(std::move(descriptors)), image_size_(image_size) {
    if (descriptors_.is_cpu()) {
      // A header over the tensor's memory: the float matcher reads it without a copy.
      descriptor_rows_ = std::make_unique<FloatTrainRows>(cv::Mat(static_cast<int>(descriptors_.size(0)),
                                                                  static_cast<int>(descriptors_.size(1)), CV_32F,
                                                                  descriptors_.data_ptr<float>()));
    }
  }
  int num_features() const override { return static_cast<int>(keypoints_.size()); }
  cv::Size image_size() const override { return image_size_; }
  const std::vector<cv::Point2f>& keypoints() const { return keypoints_; }
  const torch::Tensor& descriptor_tensor() const { return descriptors_; }  // (n, 64) on the model's device
  // L2-normalised CV_32F rows, for localization's ranking of key images.
  cv::Mat descriptors() const override {
    if (descriptor_rows_) return descriptor_rows_->rows();
    const torch::Tensor cpu = descriptors_.to(torch::kCPU).contiguous();
    return cv::Mat(static_cast<int>(cpu.size(0)), static_cast<int>(cpu.size(1)), CV_32F, cpu.data_ptr<float>()).clone();
  }
  // The same rows, for the float matcher; CPU only.
  const FloatTrainRows& descriptor_rows() const { return *descriptor_rows_; }

 private:
  std::vector<cv::Point2f> keypoints_;
  torch::Tensor descriptors_;
  std::unique_ptr<const FloatTrainRows> descriptor_rows_;  // a header over the tensor's memory
  cv::Size image_size_;
};

class XfeatMatcher : public Matcher {
 public:
  XfeatMatcher(const XfeatMatcherOptions& options, const neural::XfeatWeights& weights, std::string weights_path)
      : options_(options),
        weights_path_(std::move(weights_path)),
        layout_(weights.layout),
        model_(weights.folded, neural::ParseTorchDevice(options.device)) {}

  std::string name() const override { return "xfeat"; }

  // Upstream's network input is the mean of B, G and R (taken inside the network), not a luminance.
  bool reads_color() const override { return true; }

  std::shared_ptr<const ImageFeatures> Extract(const cv::Mat& gray) const override {
    return ExtractPixels(PixelsOfFrame(gray, cv::Mat()));
  }

  std::shared_ptr<const ImageFeatures> ExtractFrame(const cv::Mat& gray, const cv::Mat& bgr) const override {
    return ExtractPixels(PixelsOfFrame(gray, bgr));
  }

  // The mask reaches the detector: the peaks outside it are dropped before the top_k best are taken, so the mask keeps
  // the whole budget within it (dropping keypoints after detection left a fraction of top_k where it binds).
  std::shared_ptr<const ImageFeatures> ExtractFrameWithin(const cv::Mat& gray, const cv::Mat& bgr,
                                                          const cv::Mat& keep) const override {
    if (keep.type() != CV_8UC1 || keep.size() != gray.size()) {
      throw std::invalid_argument("XfeatMatcher::ExtractFrameWithin: the mask must be 8-bit, of the image's size");
    }
    return ExtractPixels(PixelsOfFrame(gray, bgr), keep);
  }

  TentativeMatches Match(const ImageFeatures& features0, const ImageFeatures& features1) const override {
    const auto* f0 = dynamic_cast<const XfeatFeatures*>(&features0);
    const auto* f1 = dynamic_cast<const XfeatFeatures*>(&features1);
    if (!f0 || !f1) throw std::invalid_argument("XfeatMatcher::Match: features from another matcher");
    TentativeMatches matches;
    auto add = [&](int i0, int i1, float similarity) {
      matches.points0.push_back(f0->keypoints()[i0]);
      matches.points1.push_back(f1->keypoints()[i1]);
      matches.scores.push_back(similarity);
    };
    if (model_.device().is_cpu()) {
      for (const FloatMatch& m :
           MatchFloatDescriptors(f0->descriptor_rows().rows(), f1->descriptor_rows(), MinSimilarity())) {
        add(m.query, m.train, m.similarity);
      }
      return matches;
    }
    torch::InferenceMode guard;
    const auto [pairs, similarity] =
        neural::XfeatMatch(f0->descriptor_tensor(), f1->descriptor_tensor(), options_.min_similarity);
    const auto pairs_cpu = pairs.to(torch::kCPU).contiguous();
    const auto similarity_cpu = similarity.to(torch::kCPU).contiguous();
    const int64_t* index = pairs_cpu.data_ptr<int64_t>();
    for (int64_t k = 0; k < pairs_cpu.size(0); ++k) {
      add(static_cast<int>(index[2 * k]), static_cast<int>(index[2 * k + 1]), similarity_cpu[k].item<float>());
    }
    return matches;
  }

  std::string DescribeOptionsJson() const override {
    nlohmann::json j{{"type", "xfeat"},
                     {"weights", EncodeFileName(weights_path_)},
                     {"weights_layout", neural::XfeatLayoutName(layout_)},
                     {"device", options_.device},
                     {"top_k", options_.top_k},
                     {"detection_threshold", options_.detection_threshold},
                     {"min_similarity", options_.min_similarity}};
    return j.dump();
  }

  std::string SerializeFeatures(const ImageFeatures& features) const override {
    const auto& f = dynamic_cast<const XfeatFeatures&>(features);
    return EncodePointFeatures(kFeaturesTag, {f.image_size(), f.keypoints(), f.descriptors()});
  }

  std::shared_ptr<const ImageFeatures> DeserializeFeatures(std::string_view bytes) const override {
    std::optional<PointFeatureRows> read = DecodePointFeatures(kFeaturesTag, bytes);
    if (!read) return nullptr;
    const int64_t dimensions = read->descriptors.empty() ? 64 : read->descriptors.cols;
    torch::Tensor rows =
        read->descriptors.empty()
            ? torch::zeros({0, dimensions}, torch::kFloat32)
            : torch::from_blob(read->descriptors.data, {read->descriptors.rows, dimensions}, torch::kFloat32).clone();
    return std::make_shared<XfeatFeatures>(std::move(read->keypoints), rows.to(model_.device()), read->image_size);
  }

 private:
  // What the network reads of a frame: its colour image when given (checked), else its grey one.
  static cv::Mat PixelsOfFrame(const cv::Mat& gray, const cv::Mat& bgr) {
    if (gray.empty() || gray.type() != CV_8UC1) throw InputError("XFeat needs an 8-bit single-channel image");
    if (bgr.empty()) return gray;
    if (bgr.type() != CV_8UC3 || bgr.size() != gray.size()) {
      throw InputError("XFeat needs the colour image as 8-bit BGR of the grey image's size");
    }
    return bgr;
  }

  // `image`: 8-bit, 1 channel (grey) or 3 (BGR, in upstream's channel order; the network averages them).
  // `keep`: a camera mask of the image's size (XfeatDetectOptions::keep), empty: none.
  std::shared_ptr<const ImageFeatures> ExtractPixels(const cv::Mat& image, const cv::Mat& keep = cv::Mat()) const {
    if (image.cols < kMinimumSide || image.rows < kMinimumSide) {
      throw InputError("image of " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                       " is smaller than the 32x32 XFeat needs");
    }
    const cv::Mat pixels = image.isContinuous() ? image : image.clone();
    UseThreads();
    torch::InferenceMode guard;
    // uint8 -> float32, then a true division by 255, as upstream's parse_input (not * (1/255): not bit-equal).
    const auto tensor = torch::from_blob(pixels.data, {1, pixels.rows, pixels.cols, pixels.channels()}, torch::kUInt8)
                            .permute({0, 3, 1, 2})
                            .to(torch::kFloat32)
                            .div_(255.0);
    neural::XfeatDetectOptions detect;
    detect.top_k = options_.top_k;
    detect.detection_threshold = options_.detection_threshold;
    detect.keep = keep;
    const neural::XfeatDetections found = model_.DetectAndCompute(tensor, detect);
    const auto keypoints = found.keypoints.to(torch::kCPU).contiguous();
    std::vector<cv::Point2f> points;
    points.reserve(static_cast<size_t>(keypoints.size(0)));
    const float* xy = keypoints.data_ptr<float>();
    for (int64_t k = 0; k < keypoints.size(0); ++k) points.emplace_back(xy[2 * k], xy[2 * k + 1]);
    return std::make_shared<XfeatFeatures>(std::move(points), found.descriptors, image.size());
  }

  // Upstream keeps a similarity strictly above min_cossim (compared in float32), and filters nothing when
  // min_cossim <= 0; the float matcher keeps similarities >= its threshold.
  float MinSimilarity() const {
    if (options_.min_similarity <= 0) return -std::numeric_limits<float>::infinity();
    return std::nextafter(static_cast<float>(options_.min_similarity), std::numeric_limits<float>::infinity());
  }

  // OpenMP thread counts belong to the calling thread, so they are set on every call, not once.
  void UseThreads() const {
    if (options_.num_threads > 0 && at::get_num_threads() != options_.num_threads) {
      at::set_num_threads(options_.num_threads);
    }
  }

  XfeatMatcherOptions options_;
  std::string weights_path_;
  neural::XfeatLayout layout_;
  neural::XfeatModel model_;
};

}  // namespace

std::unique_ptr<Matcher> CreateXfeatMatcher(const XfeatMatcherOptions& options) {
  options.Check();
  const std::string path = neural::LocateWeights("xfeat", options.weights);
  return std::make_unique<XfeatMatcher>(options, neural::LoadXfeatWeights(path), path);
}

std::string XfeatWeightsLayoutOfFile(const std::string& path) {
  const auto weights = neural::ReadXfeatStateDict(path);
  return neural::XfeatLayoutName(neural::CheckXfeatStateDict(weights, path));
}

namespace {
// XFeat's row in the plugin's table (features/matcher_plugin.h).
const PluginMatcherRegistration kXfeatPlugin{PluginMatcherModel{
    XfeatMatcherOptions::kModelName,
    [](const ModelOptions& options) { return CreateXfeatMatcher(options.As<XfeatMatcherOptions>()); },
    [](const std::string& path) {
      return std::vector<std::string>{"xfeat (" + XfeatWeightsLayoutOfFile(path) + " layout)"};
    }}};
}  // namespace

}  // namespace vmap
