#include "vmap/neural/aliked/aliked_matcher.h"

#include <cmath>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "vmap/core/error.h"
#include "vmap/core/file_name_encoding.h"
#include "vmap/features/camera_mask.h"
#include "vmap/features/float_matcher.h"
#include "vmap/features/matcher_plugin.h"
#include "vmap/features/point_features_bytes.h"
#include "vmap/neural/aliked/aliked_model.h"
#include "vmap/neural/aliked/aliked_weights.h"
#include "vmap/neural/torch_device.h"
#include "vmap/neural/weights_store.h"

namespace vmap {

namespace {

using neural::AlikedModel;

// The localization cache's record of ALIKED features; 2: features of colour images from their colour (older
// caches, from grey, are recomputed).
constexpr std::string_view kFeaturesTag = "vmapALK2";

class AlikedFeatures : public ImageFeatures {
 public:
  AlikedFeatures(std::vector<cv::Point2f> keypoints, cv::Mat descriptors, cv::Size size)
      : keypoints_(std::move(keypoints)), descriptors_(std::move(descriptors)), size_(size) {}
  int num_features() const override { return static_cast<int>(keypoints_.size()); }
  cv::Size image_size() const override { return size_; }
  const std::vector<cv::Point2f>& keypoints() const { return keypoints_; }
  cv::Mat descriptors() const override { return descriptors_.rows(); }    // CV_32F, one L2-normalised row per keypoint
  const FloatTrainRows& descriptor_rows() const { return descriptors_; }  // the same, for the float matcher

 private:
  std::vector<cv::Point2f> keypoints_;
  FloatTrainRows descriptors_;
  cv::Size size_;
};

class AlikedMatcher : public Matcher {
 public:
  AlikedMatcher(const AlikedMatcherOptions& options, neural::AlikedConfig config, const neural::StateDict& weights,
                std::string weights_path)
      : options_(options),
        weights_path_(std::move(weights_path)),
        model_(std::move(config), weights, neural::ParseTorchDevice(options.device)) {
    dkd_.top_k = options.top_k;
    dkd_.score_threshold = options.score_threshold;
    dkd_.max_keypoints = options.max_keypoints;
  }

  std::string name() const override { return "aliked"; }

  // Upstream's demo reads the image in colour and gives the network its R, G, B channels.
  bool reads_color() const override { return true; }

  std::shared_ptr<const ImageFeatures> Extract(const cv::Mat& gray) const override {
    return ExtractPixels(PixelsOfFrame(gray, cv::Mat()));
  }

  std::shared_ptr<const ImageFeatures> ExtractFrame(const cv::Mat& gray, const cv::Mat& bgr) const override {
    return ExtractPixels(PixelsOfFrame(gray, bgr));
  }

  // The mask reaches the detector: its peaks outside are suppressed before the top_k best are taken, so the mask keeps
  // the whole budget within it. The sub-pixel refinement moves a peak by up to dkd radius pixels, so a keypoint at
  // the mask's edge may end outside it; those are dropped after.
  std::shared_ptr<const ImageFeatures> ExtractFrameWithin(const cv::Mat& gray, const cv::Mat& bgr,
                                                          const cv::Mat& keep) const override {
    if (keep.type() != CV_8UC1 || keep.size() != gray.size()) {
      throw std::invalid_argument("AlikedMatcher::ExtractFrameWithin: the mask must be 8-bit, of the image's size");
    }
    const auto all = std::static_pointer_cast<const AlikedFeatures>(ExtractPixels(PixelsOfFrame(gray, bgr), keep));
    std::vector<cv::Point2f> points;
    cv::Mat rows;
    for (int i : KeptPointIndices(keep, all->keypoints())) {
      points.push_back(all->keypoints()[i]);
      rows.push_back(all->descriptors().row(i));
    }
    return std::make_shared<AlikedFeatures>(std::move(points), rows, all->image_size());
  }

  TentativeMatches Match(const ImageFeatures& features0, const ImageFeatures& features1) const override {
    const auto* f0 = dynamic_cast<const AlikedFeatures*>(&features0);
    const auto* f1 = dynamic_cast<const AlikedFeatures*>(&features1);
    if (!f0 || !f1) throw std::invalid_argument("AlikedMatcher::Match: features from another matcher");
    TentativeMatches matches;
    for (const auto& m :
         MatchFloatDescriptors(f0->descriptors(), f1->descriptor_rows(), static_cast<float>(options_.min_similarity))) {
      matches.points0.push_back(f0->keypoints()[m.query]);
      matches.points1.push_back(f1->keypoints()[m.train]);
      matches.scores.push_back(m.similarity);
    }
    return matches;
  }

  std::string DescribeOptionsJson() const override {
    nlohmann::json j{{"type", "aliked"},
                     {"model", "aliked-" + model_.config().name},
                     {"weights", EncodeFileName(weights_path_)},
                     {"device", options_.device},
                     {"top_k", options_.top_k},
                     {"min_similarity", options_.min_similarity},
                     {"longest_side", options_.longest_side},
                     {"nms_radius", dkd_.radius},
                     {"sub_pixel", dkd_.sub_pixel}};
    if (options_.top_k == 0) {
      j["score_threshold"] = options_.score_threshold;
      j["max_keypoints"] = options_.max_keypoints;
    }
    return j.dump();
  }

  std::string SerializeFeatures(const ImageFeatures& features) const override {
    const auto& f = dynamic_cast<const AlikedFeatures&>(features);
    return EncodePointFeatures(kFeaturesTag, {f.image_size(), f.keypoints(), f.descriptors()});
  }

  std::shared_ptr<const ImageFeatures> DeserializeFeatures(std::string_view bytes) const override {
    std::optional<PointFeatureRows> read = DecodePointFeatures(kFeaturesTag, bytes);
    if (!read) return nullptr;
    return std::make_shared<AlikedFeatures>(std::move(read->keypoints), std::move(read->descriptors), read->image_size);
  }

 private:
  // What the network reads of a frame: its colour image as RGB when given (checked), else its grey one.
  static cv::Mat PixelsOfFrame(const cv::Mat& gray, const cv::Mat& bgr) {
    if (gray.empty() || gray.type() != CV_8UC1) throw InputError("ALIKED needs an 8-bit single-channel image");
    if (bgr.empty()) return gray;
    if (bgr.type() != CV_8UC3 || bgr.size() != gray.size()) {
      throw InputError("ALIKED needs the colour image as 8-bit BGR of the grey image's size");
    }
    cv::Mat rgb;
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
    return rgb;
  }

  // `image`: 8-bit grey or RGB.
  // `keep`: a camera mask of the image's size, empty: none; DkdOptions::keep is it at the network image's pixels
  // (each at the image pixel its centre maps to, as the keypoints are mapped back).
  std::shared_ptr<const ImageFeatures> ExtractPixels(const cv::Mat& image, const cv::Mat& keep = cv::Mat()) const {
    cv::Mat net_image = image;
    const int longest = std::max(image.cols, image.rows);
    if (options_.longest_side > 0 && longest > options_.longest_side) {
      const double scale = double(options_.longest_side) / double(longest);
      const cv::Size size(std::max(1, int(std::lround(image.cols * scale))),
                          std::max(1, int(std::lround(image.rows * scale))));
      cv::resize(image, net_image, size, 0, 0, cv::INTER_AREA);
    }
    if (!net_image.isContinuous()) net_image = net_image.clone();
    UseThreads();
    torch::InferenceMode guard;
    // uint8 -> float then / 255, as upstream's ToTensor; a grey image stands for its three equal channels.
    const auto tensor =
        torch::from_blob(net_image.data, {1, net_image.rows, net_image.cols, net_image.channels()}, torch::kUInt8)
            .permute({0, 3, 1, 2})
            .to(torch::kFloat32)
            .div_(255.0);
    const auto maps = model_.ExtractDenseMaps(tensor);
    neural::DkdOptions dkd = dkd_;
    if (!keep.empty()) dkd.keep = KeepAtNetworkPixels(keep, net_image.size(), maps.score_map);
    const auto detected = neural::DetectKeypoints(maps.score_map, dkd);
    const auto described = model_.Describe(maps, detected.keypoints);

    const auto keypoints = detected.keypoints.to(torch::kCPU).contiguous();
    const auto descriptors = described.descriptors.to(torch::kCPU).contiguous();
    const int64_t n = keypoints.size(0);
    // Normalised -> pixels of the network image (pixel centres at integers) -> pixels of `image`.
    const float half_w = float(net_image.cols - 1) / 2.f, half_h = float(net_image.rows - 1) / 2.f;
    const float sx = float(image.cols) / float(net_image.cols), sy = float(image.rows) / float(net_image.rows);
    std::vector<cv::Point2f> points;
    points.reserve(n);
    const float* k = keypoints.data_ptr<float>();
    for (int64_t i = 0; i < n; ++i) {
      const float x = (k[2 * i] + 1.f) * half_w, y = (k[2 * i + 1] + 1.f) * half_h;
      points.emplace_back((x + 0.5f) * sx - 0.5f, (y + 0.5f) * sy - 0.5f);
    }
    cv::Mat rows(static_cast<int>(n), static_cast<int>(descriptors.size(1)), CV_32F,
                 const_cast<float*>(descriptors.data_ptr<float>()));
    return std::make_shared<AlikedFeatures>(std::move(points), rows.clone(), image.size());
  }

  // The score map's (1, 1, H, W) 0/1 mask: a network pixel is kept where the image pixel its centre maps to is.
  static torch::Tensor KeepAtNetworkPixels(const cv::Mat& keep, cv::Size net_size, const torch::Tensor& score_map) {
    const int64_t height = score_map.size(2), width = score_map.size(3);
    const float sx = float(keep.cols) / float(net_size.width), sy = float(keep.rows) / float(net_size.height);
    auto mask = torch::zeros({1, 1, height, width}, torch::kFloat32);
    float* m = mask.data_ptr<float>();
    for (int64_t y = 0; y < height; ++y) {
      const long image_y = std::lrint((float(y) + 0.5f) * sy - 0.5f);
      for (int64_t x = 0; x < width; ++x) {
        const long image_x = std::lrint((float(x) + 0.5f) * sx - 0.5f);
        m[y * width + x] = KeptByMask(keep, cv::Point2f(float(image_x), float(image_y))) ? 1.f : 0.f;
      }
    }
    return mask;
  }

  // OpenMP thread counts belong to the calling thread, so they are set on every call, not once.
  void UseThreads() const {
    if (options_.num_threads > 0 && at::get_num_threads() != options_.num_threads) {
      at::set_num_threads(options_.num_threads);
    }
  }

  AlikedMatcherOptions options_;
  std::string weights_path_;
  AlikedModel model_;
  neural::DkdOptions dkd_;
};

}  // namespace

std::unique_ptr<Matcher> CreateAlikedMatcher(const AlikedMatcherOptions& options) {
  options.Check();
  const auto config = neural::AlikedPreset(options.model);
  const std::string path = neural::LocateWeights("aliked-" + options.model, options.weights);
  const auto weights = neural::ReadAlikedStateDict(path);
  neural::CheckAlikedStateDict(weights, config, path);
  return std::make_unique<AlikedMatcher>(options, config, weights, path);
}

std::vector<std::string> AlikedModelsFittingFile(const std::string& path) {
  return neural::AlikedModelsFitting(neural::ReadAlikedStateDict(path));
}

namespace {
// ALIKED's row in the plugin's table (features/matcher_plugin.h); its weights are named as `vmap weights
// --model` names them.
const PluginMatcherRegistration kAlikedPlugin{PluginMatcherModel{
    AlikedMatcherOptions::kModelName,
    [](const ModelOptions& options) { return CreateAlikedMatcher(options.As<AlikedMatcherOptions>()); },
    [](const std::string& path) {
      std::vector<std::string> fits;
      for (const auto& model : AlikedModelsFittingFile(path)) fits.push_back("aliked-" + model);
      return fits;
    }}};
}  // namespace

}  // namespace vmap
