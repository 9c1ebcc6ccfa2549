#include "vmap/neural/xfeat/xfeat_model.h"

#include <array>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "vmap/features/camera_mask.h"

namespace vmap::neural {

namespace F = torch::nn::functional;

namespace {

constexpr double kInstanceNormEps = 1e-5;  // nn.InstanceNorm2d's default, as upstream uses it
constexpr int64_t kCell = 8;               // the heads work on 8x8 cells
constexpr int64_t kSizeMultiple = 32;      // upstream resizes its input to multiples of 32
constexpr int64_t kNmsKernel = 5;

// grid_sampler's interpolation modes (F.grid_sample's mode argument).
enum GridMode : int64_t { kBilinear = 0, kNearest = 1, kBicubic = 2 };

// Upstream's InterpolateSparse2d: integer pixel positions `positions` (1, N, 2) (x, y) of an H x W image are
// normalised with the corner-aligned rule 2 p / (S - 1) - 1 but sampled with align_corners = false, as
// upstream does (see golden/README.md, "Coordinate convention"; this is not corrected on purpose).
// Returns (1, N, C), a view with the channels last.
torch::Tensor SampleAt(const torch::Tensor& map, const torch::Tensor& positions, int64_t height, int64_t width,
                       GridMode mode) {
  // Integer division of int64 tensors is a true division in float32, as in upstream's normgrid.
  const auto extent = torch::tensor({width - 1, height - 1}, positions.options());
  const auto grid = torch::div(positions, extent).mul_(2.0).sub_(1.0).unsqueeze(-2).to(map.dtype());
  const auto sampled = torch::grid_sampler(map, grid, mode, /*padding_mode=zeros*/ 0, /*align_corners=*/false);
  return sampled.permute({0, 2, 3, 1}).squeeze(-2);
}

// The 5x5 non-maximum suppression on the CPU: OpenCV's dilation is a separable, vectorised max filter whose
// border never wins (as max_pool2d's -inf padding). A maximum is exact, so the points are the same as
// upstream's, far faster than max_pool2d (docs/measurements/code-choices.md, "XFeat on the CPU").
// Returns (N, 2) int64 (x, y) in row-major order, as nonzero() gives them.
torch::Tensor LocalMaximaOnCpu(const torch::Tensor& heatmap, double threshold) {
  const auto heat = heatmap.contiguous();
  const cv::Mat values(static_cast<int>(heat.size(2)), static_cast<int>(heat.size(3)), CV_32F, heat.data_ptr<float>());
  cv::Mat local_max;
  cv::dilate(values, local_max, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(kNmsKernel, kNmsKernel)));
  const float above = static_cast<float>(threshold);  // upstream compares in float32
  std::vector<int64_t> xy;
  for (int y = 0; y < values.rows; ++y) {
    const float* value = values.ptr<float>(y);
    const float* maximum = local_max.ptr<float>(y);
    for (int x = 0; x < values.cols; ++x) {
      if (value[x] > above && value[x] == maximum[x]) {
        xy.push_back(x);
        xy.push_back(y);
      }
    }
  }
  return torch::from_blob(xy.data(), {static_cast<int64_t>(xy.size() / 2), 2}, torch::kInt64).clone();
}

// The peaks (N, 2) int64 (x, y) in network pixels whose keypoint, scaled to the given image as DetectAndCompute
// scales it (float32), is kept by the camera mask `keep`.
torch::Tensor PeaksWithin(const cv::Mat& keep, const torch::Tensor& peaks, const torch::Tensor& scale) {
  const auto xy = peaks.to(torch::kCPU).contiguous();
  const auto factor = scale.to(torch::kCPU);
  const float scale_x = factor[0].item<float>(), scale_y = factor[1].item<float>();
  const int64_t* p = xy.data_ptr<int64_t>();
  std::vector<int64_t> kept;
  for (int64_t i = 0; i < xy.size(0); ++i) {
    const cv::Point2f keypoint(static_cast<float>(p[2 * i]) * scale_x, static_cast<float>(p[2 * i + 1]) * scale_y);
    if (KeptByMask(keep, keypoint)) kept.push_back(i);
  }
  const auto index = torch::from_blob(kept.data(), {static_cast<int64_t>(kept.size())}, torch::kInt64).clone();
  return peaks.index_select(0, index.to(peaks.device()));
}

// LibTorch's bicubic convolution coefficients (A = -0.75) for a fractional position t.
std::array<float, 4> CubicCoefficients(float t) {
  constexpr float A = -0.75f;
  auto near = [&](float x) { return ((A + 2) * x - (A + 3)) * x * x + 1; };       // |x| <= 1
  auto far = [&](float x) { return ((A * x - 5 * A) * x + 8 * A) * x - 4 * A; };  // 1 < |x| < 2
  return {far(t + 1.0f), near(t), near(1.0f - t), far(1.0f - t + 1.0f)};
}

// Upstream's descriptor sampling on the CPU: grid_sample(bicubic, align_corners = false, zeros padding) of
// the (1, C, h, w) map at the integer points (x, y) of the H x W network input, normalised with upstream's
// normgrid, then each row L2-normalised. The arithmetic is LibTorch's, point by point over channel-last
// memory, far faster than grid_sampler + normalize (docs/measurements/code-choices.md, "XFeat on the CPU").
torch::Tensor SampleDescriptorsOnCpu(const torch::Tensor& map, const torch::Tensor& points, int64_t height,
                                     int64_t width) {
  const auto channels_last = map[0].permute({1, 2, 0}).contiguous();  // (h, w, C)
  const int64_t map_h = channels_last.size(0), map_w = channels_last.size(1), c = channels_last.size(2);
  const float* values = channels_last.data_ptr<float>();
  const std::vector<float> zeros(static_cast<size_t>(c), 0.f);  // the padding around the map
  const auto xy = points.contiguous();
  const int64_t* p = xy.data_ptr<int64_t>();
  auto out = torch::empty({xy.size(0), c}, torch::kFloat32);
  float* rows = out.data_ptr<float>();
  std::vector<float> row_sums(static_cast<size_t>(4 * c));
  auto source = [](int64_t point, int64_t input_size, int64_t map_size) {
    // normgrid (2 p / (S - 1) - 1, in float32 as upstream's int64 true division), then grid_sample's
    // unnormalisation for align_corners = false.
    const float g = static_cast<float>(point) / static_cast<float>(input_size - 1) * 2.f - 1.f;
    return ((g + 1.f) * static_cast<float>(map_size) - 1.f) / 2.f;
  };
  for (int64_t k = 0; k < xy.size(0); ++k) {
    const float ix = source(p[2 * k], width, map_w), iy = source(p[2 * k + 1], height, map_h);
    const float x0 = std::floor(ix), y0 = std::floor(iy);
    const auto cx = CubicCoefficients(ix - x0), cy = CubicCoefficients(iy - y0);
    for (int i = 0; i < 4; ++i) {
      const int64_t y = static_cast<int64_t>(y0) - 1 + i;
      std::array<const float*, 4> tap;
      for (int j = 0; j < 4; ++j) {
        const int64_t x = static_cast<int64_t>(x0) - 1 + j;
        const bool inside = y >= 0 && y < map_h && x >= 0 && x < map_w;
        tap[j] = inside ? values + (y * map_w + x) * c : zeros.data();
      }
      float* sum = row_sums.data() + i * c;
      for (int64_t ch = 0; ch < c; ++ch) {
        sum[ch] = tap[0][ch] * cx[0] + tap[1][ch] * cx[1] + tap[2][ch] * cx[2] + tap[3][ch] * cx[3];
      }
    }
    float* row = rows + k * c;
    const float* s = row_sums.data();
    float squares = 0.f;
    for (int64_t ch = 0; ch < c; ++ch) {
      row[ch] = s[ch] * cy[0] + s[c + ch] * cy[1] + s[2 * c + ch] * cy[2] + s[3 * c + ch] * cy[3];
      squares += row[ch] * row[ch];
    }
    const float norm = std::max(std::sqrt(squares), 1e-12f);  // F.normalize: x / max(|x|, eps)
    for (int64_t ch = 0; ch < c; ++ch) row[ch] /= norm;
  }
  return out;
}

}  // namespace

const std::vector<XfeatConv>& XfeatConvolutions() {
  static const std::vector<XfeatConv> convs{
      {"skip1.1", 24, 1, 1, 1, false},          {"block1.0", 4, 1, 3, 1, true},
      {"block1.1", 8, 4, 3, 2, true},           {"block1.2", 8, 8, 3, 1, true},
      {"block1.3", 24, 8, 3, 2, true},          {"block2.0", 24, 24, 3, 1, true},
      {"block2.1", 24, 24, 3, 1, true},         {"block3.0", 64, 24, 3, 2, true},
      {"block3.1", 64, 64, 3, 1, true},         {"block3.2", 64, 64, 1, 1, true},
      {"block4.0", 64, 64, 3, 2, true},         {"block4.1", 64, 64, 3, 1, true},
      {"block4.2", 64, 64, 3, 1, true},         {"block5.0", 128, 64, 3, 2, true},
      {"block5.1", 128, 128, 3, 1, true},       {"block5.2", 128, 128, 3, 1, true},
      {"block5.3", 64, 128, 1, 1, true},        {"block_fusion.0", 64, 64, 3, 1, true},
      {"block_fusion.1", 64, 64, 3, 1, true},   {"block_fusion.2", 64, 64, 1, 1, false},
      {"heatmap_head.0", 64, 64, 1, 1, true},   {"heatmap_head.1", 64, 64, 1, 1, true},
      {"heatmap_head.2", 1, 64, 1, 1, false},   {"keypoint_head.0", 64, 64, 1, 1, true},
      {"keypoint_head.1", 64, 64, 1, 1, true},  {"keypoint_head.2", 64, 64, 1, 1, true},
      {"keypoint_head.3", 65, 64, 1, 1, false},
  };
  return convs;
}

XfeatModel::XfeatModel(const StateDict& weights, torch::Device device) : device_(device) {
  torch::InferenceMode guard;
  for (const XfeatConv& conv : XfeatConvolutions()) {
    const auto weight = weights.find(conv.weight_key());
    const auto bias = weights.find(conv.bias_key());
    if (weight == weights.end() || bias == weights.end()) {
      throw std::invalid_argument("XfeatModel: missing weight of " + conv.name + " (check the file first)");
    }
    convs_.emplace(conv.name, conv);
    weights_[conv.name] = {weight->second.to(device_, torch::kFloat32).contiguous(),
                           bias->second.to(device_, torch::kFloat32).contiguous()};
  }
  if (device_.is_cpu() && at::hasMKLDNN()) {
    for (const auto& [name, tensors] : weights_) {
      const XfeatConv& conv = convs_.at(name);
      const auto weight = torch::mkldnn_reorder_conv2d_weight(
          tensors.first.to_mkldnn(), {conv.kernel / 2, conv.kernel / 2}, {conv.stride, conv.stride}, {1, 1}, 1);
      blocked_weights_[name] = {weight, tensors.second};
    }
  }
}

torch::Tensor XfeatModel::Conv(const torch::Tensor& x, const std::string& name) const {
  const XfeatConv& conv = convs_.at(name);
  torch::Tensor y;
  if (x.is_mkldnn()) {
    const auto& [weight, bias] = blocked_weights_.at(name);
    y = torch::mkldnn_convolution(x, weight, bias, {conv.kernel / 2, conv.kernel / 2}, {conv.stride, conv.stride},
                                  {1, 1}, 1);
  } else {
    const auto& [weight, bias] = weights_.at(name);
    y = torch::conv2d(x, weight, bias, conv.stride, conv.kernel / 2);
  }
  // A BasicLayer ends with a ReLU (its BatchNorm is folded into the weights); the plain convs have none.
  return conv.batch_norm ? torch::relu_(y) : y;
}

torch::Tensor XfeatModel::FirstConvOnCpu(const torch::Tensor& x) const {
  // block1.0 reads one channel at full resolution, where oneDNN is slow: cv::filter2D (a correlation, as
  // conv2d) is several times faster (docs/measurements/code-choices.md, "XFeat on the CPU").
  const auto& [weight, bias] = weights_.at("block1.0");
  const int height = static_cast<int>(x.size(2)), width = static_cast<int>(x.size(3));
  auto out = torch::empty({x.size(0), weight.size(0), x.size(2), x.size(3)}, x.options());
  for (int64_t b = 0; b < x.size(0); ++b) {
    const cv::Mat image(height, width, CV_32F, x[b][0].data_ptr<float>());
    for (int64_t c = 0; c < weight.size(0); ++c) {
      const cv::Mat kernel(3, 3, CV_32F, weight[c][0].data_ptr<float>());
      cv::Mat channel(height, width, CV_32F, out[b][c].data_ptr<float>());
      cv::filter2D(image, channel, CV_32F, kernel, cv::Point(-1, -1), bias[c].item<float>(), cv::BORDER_CONSTANT);
    }
  }
  return out.relu_();
}

XfeatNetOutput XfeatModel::Forward(const torch::Tensor& image, bool reference_ops) const {
  torch::InferenceMode guard;
  if (image.dim() != 4 || (image.size(1) != 1 && image.size(1) != 3) || image.size(2) % kCell != 0 ||
      image.size(3) % kCell != 0 || image.size(2) == 0 || image.size(3) == 0) {
    throw std::invalid_argument("XfeatModel::Forward: expected (B, 1 or 3, H, W) with H, W positive multiples of 8");
  }
  // On the CPU the activations stay in oneDNN's blocked layout from layer to layer, with the weights
  // reordered once: faster than LibTorch's conv2d, which reorders both at every call
  // (docs/measurements/code-choices.md, "XFeat on the CPU").
  const bool on_cpu = device_.is_cpu() && !reference_ops;
  const bool blocked = on_cpu && !blocked_weights_.empty();
  auto to_blocked = [&](const torch::Tensor& t) { return blocked ? t.to_mkldnn() : t; };
  auto to_dense = [](const torch::Tensor& t) { return t.is_mkldnn() ? t.to_dense() : t; };

  auto x = image.to(device_, torch::kFloat32);
  // The network sees grey: the mean of the channels (the mean of one channel is that channel, bit for bit).
  if (x.size(1) != 1) x = x.mean(1, /*keepdim=*/true);
  x = torch::instance_norm(x, {}, {}, {}, {}, /*use_input_stats=*/true, /*momentum=*/0.1, kInstanceNormEps,
                           /*cudnn_enabled=*/true)
          .contiguous();

  auto first = on_cpu ? to_blocked(FirstConvOnCpu(x)) : Conv(x, "block1.0");
  auto x1 = Conv(Conv(Conv(first, "block1.1"), "block1.2"), "block1.3");
  auto skip = Conv(to_blocked(torch::avg_pool2d(x, {4, 4}, {4, 4})), "skip1.1");
  auto x2 = Conv(Conv(x1.add_(skip), "block2.0"), "block2.1");
  auto x3 = Conv(Conv(Conv(x2, "block3.0"), "block3.1"), "block3.2");
  auto x4 = Conv(Conv(Conv(x3, "block4.0"), "block4.1"), "block4.2");
  auto x5 = Conv(Conv(Conv(Conv(x4, "block5.0"), "block5.1"), "block5.2"), "block5.3");
  const std::vector<int64_t> size3{x3.size(2), x3.size(3)};
  auto up4 = torch::upsample_bilinear2d(to_dense(x4), size3, /*align_corners=*/false);
  auto up5 = torch::upsample_bilinear2d(to_dense(x5), size3, /*align_corners=*/false);
  // (x3 + x4) + x5, the order upstream sums them in.
  auto fused = to_blocked(to_dense(x3).add(up4).add_(up5));
  XfeatNetOutput out;
  const auto descriptor_map = Conv(Conv(Conv(fused, "block_fusion.0"), "block_fusion.1"), "block_fusion.2");
  out.descriptor_map = to_dense(descriptor_map);
  out.reliability =
      to_dense(Conv(Conv(Conv(descriptor_map, "heatmap_head.0"), "heatmap_head.1"), "heatmap_head.2")).sigmoid_();
  // The keypoint head reads the image itself, each 8x8 cell as 64 channels (channel 8 dy + dx).
  auto cells = to_blocked(torch::pixel_unshuffle(x, kCell).contiguous());
  out.keypoint_logits = to_dense(
      Conv(Conv(Conv(Conv(cells, "keypoint_head.0"), "keypoint_head.1"), "keypoint_head.2"), "keypoint_head.3"));
  return out;
}

XfeatDetections XfeatModel::DetectAndCompute(const torch::Tensor& image, const XfeatDetectOptions& options) const {
  torch::InferenceMode guard;
  if (image.dim() != 4 || image.size(0) != 1) {
    throw std::invalid_argument("XfeatModel::DetectAndCompute: expected one image (1, C, H, W)");
  }
  const int64_t height = image.size(2), width = image.size(3);
  const int64_t net_height = height / kSizeMultiple * kSizeMultiple;
  const int64_t net_width = width / kSizeMultiple * kSizeMultiple;
  if (net_height == 0 || net_width == 0) {
    throw std::invalid_argument("XfeatModel::DetectAndCompute: the image must be at least 32 x 32");
  }
  auto x = image.to(device_, torch::kFloat32);
  // Upstream always resizes; at the same size bilinear interpolation is an exact copy, so it is skipped.
  if (net_height != height || net_width != width) {
    x = torch::upsample_bilinear2d(x, {net_height, net_width}, /*align_corners=*/false);
  }

  XfeatDetections out;
  out.net_height = net_height;
  out.net_width = net_width;
  if (options.keep_intermediates) out.net_input = x;
  XfeatNetOutput net = Forward(x, options.upstream_network_ops);
  const auto descriptor_map = F::normalize(net.descriptor_map, F::NormalizeFuncOptions().p(2).dim(1).eps(1e-12));

  // Keypoint probability of each pixel: softmax over the 65 bins, the 64 pixel bins back to their places.
  const auto heatmap = torch::pixel_shuffle(torch::softmax(net.keypoint_logits, 1).slice(1, 0, kCell * kCell), kCell);

  // 5x5 non-maximum suppression: a pixel equal to the maximum of its neighbourhood and above the threshold.
  const bool on_cpu = device_.is_cpu() && !options.upstream_postprocessing_ops;
  torch::Tensor nms_keypoints;  // (N, 2) (x, y), row-major
  if (on_cpu) {
    nms_keypoints = LocalMaximaOnCpu(heatmap, options.detection_threshold);
  } else {
    const auto local_max =
        torch::max_pool2d(heatmap, {kNmsKernel, kNmsKernel}, {1, 1}, {kNmsKernel / 2, kNmsKernel / 2});
    const auto is_peak = heatmap.eq(local_max).logical_and_(heatmap.gt(options.detection_threshold));
    nms_keypoints = is_peak[0].nonzero().slice(1, 1, 3).flip({-1});
  }
  // Back to the given image: float32 (x, y) times float32 (W / W', H / H'), as upstream scales them.
  const auto scale = torch::tensor(
      {static_cast<float>(double(width) / double(net_width)), static_cast<float>(double(height) / double(net_height))},
      torch::TensorOptions().dtype(torch::kFloat32).device(device_));
  if (!options.keep.empty()) nms_keypoints = PeaksWithin(options.keep, nms_keypoints, scale);
  if (options.keep_intermediates) {
    out.heatmap = heatmap;
    out.nms_keypoints = nms_keypoints;
  }
  if (nms_keypoints.size(0) == 0) {  // a blank image: no keypoints at all
    const auto floats = torch::TensorOptions().dtype(torch::kFloat32).device(device_);
    out.keypoints = torch::zeros({0, 2}, floats);
    out.scores = torch::zeros({0}, floats);
    out.descriptors = torch::zeros({0, descriptor_map.size(1)}, floats);
    if (options.keep_intermediates) out.net = std::move(net);
    return out;
  }

  // Score = heatmap (nearest) x reliability (bilinear), sampled as upstream does; (0, 0) is marked invalid.
  const auto positions = nms_keypoints.unsqueeze(0);
  auto scores = SampleAt(heatmap, positions, net_height, net_width, kNearest)
                    .mul(SampleAt(net.reliability, positions, net_height, net_width, kBilinear))
                    .squeeze(-1);  // (1, N)
  scores.index_put_({positions.eq(0).all(-1)}, -1.0);

  const auto order = torch::argsort(-scores);  // upstream's unstable descending sort
  const auto topk_idx = order.slice(1, 0, options.top_k)[0];
  auto keypoints = nms_keypoints.index_select(0, topk_idx);
  auto kept_scores = scores[0].index_select(0, topk_idx);
  // Points on the last row or column sample outside the heatmap and score 0: upstream drops score <= 0.
  const auto valid = kept_scores.gt(0);
  if (!valid.all().item<bool>()) {
    keypoints = keypoints.index({valid});
    kept_scores = kept_scores.index({valid});
  }

  torch::Tensor descriptors;
  if (on_cpu) {
    descriptors = SampleDescriptorsOnCpu(descriptor_map, keypoints, net_height, net_width);
  } else {
    descriptors = SampleAt(descriptor_map, keypoints.unsqueeze(0), net_height, net_width, kBicubic)[0];
    descriptors = F::normalize(descriptors, F::NormalizeFuncOptions().p(2).dim(-1).eps(1e-12));
  }
  out.keypoints = keypoints.mul(scale);
  out.scores = kept_scores;
  out.descriptors = descriptors.contiguous();
  if (options.keep_intermediates) {
    out.net = std::move(net);
    out.nms_scores = scores[0];
    out.topk_idx = topk_idx;
  }
  return out;
}

}  // namespace vmap::neural

namespace vmap::neural {

std::pair<torch::Tensor, torch::Tensor> XfeatMatch(const torch::Tensor& descriptors0, const torch::Tensor& descriptors1,
                                                   double min_cossim) {
  torch::InferenceMode guard;
  const auto long_options = torch::TensorOptions().dtype(torch::kInt64).device(descriptors0.device());
  if (descriptors0.size(0) == 0 || descriptors1.size(0) == 0) {
    return {torch::zeros({0, 2}, long_options), torch::zeros({0}, descriptors0.options())};
  }
  const auto similarity = descriptors0.mm(descriptors1.t());
  const auto [best, match01] = similarity.max(1);
  const auto match10 = descriptors1.mm(descriptors0.t()).argmax(1);
  const auto index0 = torch::arange(descriptors0.size(0), long_options);
  auto keep = match10.index_select(0, match01).eq(index0);
  if (min_cossim > 0) keep.logical_and_(best.gt(min_cossim));
  return {torch::stack({index0.index({keep}), match01.index({keep})}, 1), best.index({keep})};
}

}  // namespace vmap::neural
