#include "vmap/neural/aliked/aliked_model.h"

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "vmap/neural/aliked/deform_conv.h"

namespace vmap::neural {

namespace F = torch::nn::functional;
using torch::indexing::Slice;

namespace {

constexpr double kBatchNormEps = 1e-5;  // PyTorch's BatchNorm2d default, used by every ALIKED block
constexpr int kPadMultiple = 32;        // the network downsamples by 32
constexpr int kLevelScale[4] = {1, 2, 8, 32};

// Source rows (or columns) and weights of a bilinear align_corners upsampling from `in_size` to `out_size`
// at output positions `positions` (int64), computed as LibTorch's CPU kernel does: the scale is
// float(in - 1) / (out - 1), the source index is scale * position in float, truncated.
struct LinearTaps {
  torch::Tensor index0, index1;    // int64
  torch::Tensor weight0, weight1;  // float
};

LinearTaps UpsampleTaps(const torch::Tensor& positions, int64_t in_size, int64_t out_size) {
  LinearTaps taps;
  if (in_size == out_size) {
    taps.index0 = positions;
    taps.index1 = positions;
    taps.weight0 = torch::ones(positions.sizes(), positions.options().dtype(torch::kFloat32));
    taps.weight1 = torch::zeros_like(taps.weight0);
    return taps;
  }
  const float scale = out_size > 1 ? static_cast<float>(in_size - 1) / static_cast<float>(out_size - 1) : 0.f;
  auto real = positions.to(torch::kFloat32).mul_(scale);
  taps.index0 = real.to(torch::kLong);
  taps.index1 = torch::where(taps.index0 < in_size - 1, taps.index0 + 1, taps.index0);
  taps.weight1 = (real - taps.index0.to(torch::kFloat32)).clamp_(0.0, 1.0);
  taps.weight0 = 1.0 - taps.weight1;
  return taps;
}

// Replicate padding to a multiple of 32, split evenly with the smaller half first (upstream's InputPadder).
int64_t PadBefore(int64_t size) {
  const int64_t pad = (kPadMultiple - size % kPadMultiple) % kPadMultiple;
  return pad / 2;
}
int64_t PadTotal(int64_t size) { return (kPadMultiple - size % kPadMultiple) % kPadMultiple; }

}  // namespace

// ------------------------------------------------------------------------------------------------- DKD

namespace {

// Maximum over the (2r+1) x (2r+1) window around each pixel, clipped at the borders (max_pool2d's -inf
// padding), as a row pass and a column pass: the maximum is exact in any order.
void WindowMax(const float* in, float* out, std::vector<float>& rows, int64_t h, int64_t w, int r) {
  rows.resize(static_cast<size_t>(h * w));
  for (int64_t y = 0; y < h; ++y) {
    const float* src = in + y * w;
    float* dst = rows.data() + y * w;
    for (int64_t x = 0; x < w; ++x) {
      float m = src[x];
      for (int64_t k = std::max<int64_t>(0, x - r); k <= std::min<int64_t>(w - 1, x + r); ++k) m = std::max(m, src[k]);
      dst[x] = m;
    }
  }
  for (int64_t y = 0; y < h; ++y) {
    float* dst = out + y * w;
    std::copy(rows.data() + y * w, rows.data() + (y + 1) * w, dst);
    for (int64_t k = std::max<int64_t>(0, y - r); k <= std::min<int64_t>(h - 1, y + r); ++k) {
      const float* src = rows.data() + k * w;
      for (int64_t x = 0; x < w; ++x) dst[x] = std::max(dst[x], src[x]);
    }
  }
}

// SimpleNms on a contiguous float CPU map, with the same arithmetic as the tensor version (comparisons and
// maxima only, so the result is identical), several times faster (docs/measurements/code-choices.md, "ALIKED on
// the CPU").
torch::Tensor SimpleNmsCpu(const torch::Tensor& scores, int radius) {
  const auto map = scores.contiguous();
  const int64_t h = map.size(-2), w = map.size(-1), n = h * w;
  const float* s = map.data_ptr<float>();
  std::vector<float> window(static_cast<size_t>(n)), rows, remaining(static_cast<size_t>(n)),
      mask(static_cast<size_t>(n)), suppressed(static_cast<size_t>(n));
  WindowMax(s, window.data(), rows, h, w, radius);
  for (int64_t i = 0; i < n; ++i) mask[i] = s[i] == window[i] ? 1.f : 0.f;
  for (int round = 0; round < 2; ++round) {
    WindowMax(mask.data(), suppressed.data(), rows, h, w, radius);
    for (int64_t i = 0; i < n; ++i) remaining[i] = suppressed[i] > 0.f ? 0.f : s[i];
    WindowMax(remaining.data(), window.data(), rows, h, w, radius);
    for (int64_t i = 0; i < n; ++i) {
      if (remaining[i] == window[i] && !(suppressed[i] > 0.f)) mask[i] = 1.f;
    }
  }
  auto out = torch::empty_like(map);
  float* o = out.data_ptr<float>();
  for (int64_t i = 0; i < n; ++i) o[i] = mask[i] > 0.f ? s[i] : 0.f;
  return out;
}

}  // namespace

torch::Tensor SimpleNms(const torch::Tensor& scores, int radius) {
  if (scores.device().is_cpu() && scores.scalar_type() == torch::kFloat32) return SimpleNmsCpu(scores, radius);
  const int64_t window = 2 * radius + 1;
  auto max_pool = [&](const torch::Tensor& x) {
    return torch::max_pool2d(x, {window, window}, {1, 1}, {radius, radius});
  };
  auto zeros = torch::zeros_like(scores);
  auto max_mask = scores == max_pool(scores);
  for (int round = 0; round < 2; ++round) {
    auto suppressed = max_pool(max_mask.to(scores.scalar_type())) > 0;
    auto remaining = torch::where(suppressed, zeros, scores);
    auto new_max = remaining == max_pool(remaining);
    max_mask = max_mask.logical_or(new_max.logical_and(suppressed.logical_not()));
  }
  return torch::where(max_mask, scores, zeros);
}

DkdResult DetectKeypoints(const torch::Tensor& score_map, const DkdOptions& options) {
  if (score_map.dim() != 4 || score_map.size(0) != 1 || score_map.size(1) != 1) {
    throw std::invalid_argument("DetectKeypoints: expected a (1, 1, H, W) score map");
  }
  const int64_t height = score_map.size(2), width = score_map.size(3);
  const int r = options.radius;
  auto nms = SimpleNms(score_map, r);
  nms.index_put_({Slice(), Slice(), Slice(0, r), Slice()}, 0.0);
  nms.index_put_({Slice(), Slice(), Slice(), Slice(0, r)}, 0.0);
  nms.index_put_({Slice(), Slice(), Slice(std::max<int64_t>(0, height - r)), Slice()}, 0.0);
  nms.index_put_({Slice(), Slice(), Slice(), Slice(std::max<int64_t>(0, width - r))}, 0.0);
  if (options.keep.defined()) nms.mul_(options.keep.to(nms.device(), nms.scalar_type()));
  auto flat_nms = nms.view({-1});
  const auto scores_flat = score_map.reshape({-1});

  torch::Tensor indices;  // flat pixel indices, int64
  if (options.top_k > 0) {
    const int64_t k = std::min<int64_t>(options.top_k, flat_nms.numel());
    auto top = torch::topk(flat_nms, k);
    indices = std::get<1>(top);
    if (options.drop_suppressed) indices = indices.index({std::get<0>(top) > 0});
  } else {
    auto mask = options.score_threshold > 0 ? flat_nms > options.score_threshold : torch::Tensor();
    if (!mask.defined() || !mask.any().item<bool>()) mask = flat_nms > scores_flat.mean();
    indices = mask.nonzero().select(1, 0);
    if (indices.numel() > options.max_keypoints) {
      auto order = std::get<1>(scores_flat.index_select(0, indices).sort(/*dim=*/0, /*descending=*/true));
      indices = indices.index_select(0, order.slice(0, 0, options.max_keypoints));
    }
  }

  const auto float_options = score_map.options();
  DkdResult result;
  if (indices.numel() == 0) {
    result.keypoints = torch::zeros({0, 2}, float_options);
    result.scores = torch::zeros({0}, float_options);
    result.dispersity = torch::zeros({0}, float_options);
    return result;
  }
  auto xy = torch::stack({indices.remainder(width), indices.div(width, "trunc")}, 1).to(torch::kFloat32);
  if (options.sub_pixel) {
    // Soft-argmax over the (2r+1)^2 window around each peak (zero outside the map, as upstream's unfold).
    const int64_t window = 2 * r + 1;
    auto grid_1d = torch::linspace(-r, r, window, float_options);
    auto grid_x = grid_1d.view({1, window}).expand({window, window}).reshape({-1});  // tap t = i*window + j: j - r
    auto grid_y = grid_1d.view({window, 1}).expand({window, window}).reshape({-1});  // i - r
    auto grid = torch::stack({grid_x, grid_y}, 1);                                   // (window^2, 2) as (x, y)
    auto padded = torch::constant_pad_nd(score_map.view({height, width}), {r, r, r, r}, 0.0).view({-1});
    auto row = indices.div(width, "trunc"), col = indices.remainder(width);
    auto tap = torch::arange(window, indices.options());
    auto patch_index = ((row.view({-1, 1, 1}) + tap.view({1, -1, 1})) * (width + 2 * r) +
                        (col.view({-1, 1, 1}) + tap.view({1, 1, -1})))
                           .view({-1});
    auto patch = padded.index_select(0, patch_index).view({indices.size(0), window * window});
    auto max_v = std::get<0>(patch.max(1)).unsqueeze(1);
    auto x_exp = ((patch - max_v) / options.temperature).exp();
    auto exp_sum = x_exp.sum(1).unsqueeze(1);
    auto residual = x_exp.matmul(grid) / exp_sum;
    auto dist2 = ((grid.unsqueeze(0) - residual.unsqueeze(1)) / double(r)).norm(2, -1).pow(2);
    result.dispersity = (x_exp * dist2).sum(1) / exp_sum.squeeze(1);
    xy = xy + residual;
  } else {
    result.dispersity = torch::zeros({indices.size(0)}, float_options);
  }
  auto wh = torch::tensor({float(width - 1), float(height - 1)}, float_options);
  result.keypoints = xy / wh * 2 - 1;
  result.scores = F::grid_sample(score_map, result.keypoints.view({1, 1, -1, 2}),
                                 F::GridSampleFuncOptions().mode(torch::kBilinear).align_corners(true))
                      .view({-1});
  return result;
}

// ------------------------------------------------------------------------------------------------- network

AlikedModel::AlikedModel(AlikedConfig config, const StateDict& weights, torch::Device device)
    : config_(std::move(config)), device_(device) {
  torch::InferenceMode guard;
  auto get = [&](const std::string& key) {
    auto it = weights.find(key);
    if (it == weights.end()) throw std::invalid_argument("AlikedModel: missing weight " + key);
    return it->second.to(torch::kFloat32);
  };
  // Inference BatchNorm is a per-channel affine map: fold it into the convolution before it.
  auto fold = [&](const std::string& conv, const std::string& bn) {
    auto scale = get(bn + ".weight") / (get(bn + ".running_var") + kBatchNormEps).sqrt();
    auto bias = get(bn + ".bias") - get(bn + ".running_mean") * scale;
    weights_[conv + ".weight"] = (get(conv + ".weight") * scale.view({-1, 1, 1, 1})).to(device_).contiguous();
    weights_[conv + ".bias"] = bias.to(device_).contiguous();
  };
  for (const auto& block : {"block1", "block2", "block3", "block4"}) {
    const bool deformable = std::string(block) >= "block3";
    for (const auto& [conv, bn] : {std::pair{".conv1", ".bn1"}, std::pair{".conv2", ".bn2"}}) {
      const std::string prefix = std::string(block) + conv;
      if (deformable) {
        fold(prefix + ".regular_conv", std::string(block) + bn);
        weights_[prefix + ".offset_conv.weight"] = get(prefix + ".offset_conv.weight").to(device_).contiguous();
        weights_[prefix + ".offset_conv.bias"] = get(prefix + ".offset_conv.bias").to(device_).contiguous();
      } else {
        fold(prefix, std::string(block) + bn);
      }
    }
    if (std::string(block) != "block1") {
      for (const char* part : {".downsample.weight", ".downsample.bias"}) {
        weights_[std::string(block) + part] = get(std::string(block) + part).to(device_).contiguous();
      }
    }
  }
  // The full- and half-resolution layers run in channels-last memory: oneDNN's 3x3 convolutions with 4-16
  // channels were faster so on this project's CPU than on NCHW tensors (bench/aliked_bench --stages;
  // docs/measurements/code-choices.md, "ALIKED on the CPU").
  for (const char* key : {"block1.conv1.weight", "block1.conv2.weight", "block2.conv1.weight", "block2.conv2.weight",
                          "block2.downsample.weight"}) {
    weights_[key] = weights_[key].contiguous(torch::MemoryFormat::ChannelsLast);
  }
  for (const char* key : {"conv1.weight", "conv2.weight", "conv3.weight", "conv4.weight", "score_head.2.weight",
                          "score_head.4.weight", "score_head.6.weight"}) {
    weights_[key] = get(key).to(device_).contiguous(torch::MemoryFormat::ChannelsLast);
  }
  for (const char* key : {"desc_head.offset_conv.0.bias", "desc_head.offset_conv.2.bias"}) {
    weights_[key] = get(key).to(device_).contiguous();
  }
  // The score head's first 1x1 convolution, split by the four feature levels it reads (see ExtractDenseMaps).
  const auto head0 = get("score_head.0.weight");
  const int64_t quarter = config_.dim / 4;
  for (int k = 0; k < 4; ++k) {
    weights_["score_head.0.level" + std::to_string(k)] =
        head0.slice(1, k * quarter, (k + 1) * quarter).to(device_).contiguous(torch::MemoryFormat::ChannelsLast);
  }
  weights_["score_head.0.weight"] = head0.to(device_).contiguous();
  // SDDH as matrix products: the offset convolution on a K x K patch is one (2M, dim*K*K) matrix.
  const int64_t offsets = 2 * config_.num_samples;
  weights_["desc_head.offset_conv.0.matrix"] =
      get("desc_head.offset_conv.0.weight").reshape({offsets, -1}).t().to(device_).contiguous();
  weights_["desc_head.offset_conv.2.matrix"] =
      get("desc_head.offset_conv.2.weight").reshape({offsets, offsets}).t().to(device_).contiguous();
  weights_["desc_head.sf_conv.matrix"] =
      get("desc_head.sf_conv.weight").reshape({config_.dim, config_.dim}).t().to(device_).contiguous();
  weights_["desc_head.agg_matrix"] = get("desc_head.agg_weights").reshape({-1, config_.dim}).to(device_).contiguous();
}

const torch::Tensor& AlikedModel::W(const std::string& key) const {
  auto it = weights_.find(key);
  if (it == weights_.end()) throw std::invalid_argument("AlikedModel: missing weight " + key);
  return it->second;
}

torch::Tensor AlikedModel::Conv(const torch::Tensor& x, const std::string& name, int64_t padding) const {
  auto bias = weights_.count(name + ".bias") ? W(name + ".bias") : torch::Tensor();
  return torch::conv2d(x, W(name + ".weight"), bias, 1, padding);
}

torch::Tensor AlikedModel::BlockConv(const torch::Tensor& x, const std::string& name, bool deformable) const {
  if (!deformable) return Conv(x, name, 1);
  // Offsets are clamped to a quarter of the map's larger side, as upstream.
  const double max_offset = double(std::max(x.size(2), x.size(3))) / 4.0;
  auto offset = Conv(x, name + ".offset_conv", 1).clamp_(-max_offset, max_offset);
  return DeformConv2d(x, offset, W(name + ".regular_conv.weight"), W(name + ".regular_conv.bias"), torch::Tensor(), 1);
}

torch::Tensor AlikedModel::Block(const torch::Tensor& x, const std::string& name, bool deformable,
                                 bool residual) const {
  auto y = torch::selu(BlockConv(x, name + ".conv1", deformable));
  y = BlockConv(y, name + ".conv2", deformable);
  if (!residual) return torch::selu(y);
  return torch::selu(y.add_(Conv(x, name + ".downsample", 0)));
}

AlikedDenseMaps AlikedModel::ExtractDenseMaps(const torch::Tensor& image_in) const {
  torch::InferenceMode guard;
  if (image_in.dim() != 4 || image_in.size(0) != 1 || (image_in.size(1) != 1 && image_in.size(1) != 3) ||
      image_in.size(2) < 1 || image_in.size(3) < 1) {
    throw std::invalid_argument("AlikedModel: expected a (1, 3, H, W) or (1, 1, H, W) image");
  }
  AlikedDenseMaps maps;
  maps.height = image_in.size(2);
  maps.width = image_in.size(3);
  maps.pad_top = PadBefore(maps.height);
  maps.pad_left = PadBefore(maps.width);
  maps.padded_height = maps.height + PadTotal(maps.height);
  maps.padded_width = maps.width + PadTotal(maps.width);
  auto image = image_in.to(device_, torch::kFloat32);
  if (maps.padded_height != maps.height || maps.padded_width != maps.width) {
    image = torch::replication_pad2d(image, {maps.pad_left, PadTotal(maps.width) - maps.pad_left, maps.pad_top,
                                             PadTotal(maps.height) - maps.pad_top});
  }
  // A grey image is its three identical channels, as upstream sees it. Three interleaved channels also keep
  // oneDNN on its fast path: the one-channel convolution was slower than the three-channel one here.
  image = image.expand({1, 3, image.size(2), image.size(3)}).contiguous(torch::MemoryFormat::ChannelsLast);

  torch::Tensor x[4];
  x[0] = Block(image, "block1", false, false);
  x[1] = Block(torch::avg_pool2d(x[0], 2, 2), "block2", false, true);
  // From 1/8 on the maps are small; the deformable blocks work on NCHW.
  x[2] = Block(torch::avg_pool2d(x[1], 4, 4).contiguous(), "block3", true, true);
  x[3] = Block(torch::avg_pool2d(x[2], 4, 4), "block4", true, true);
  for (int k = 0; k < 4; ++k) {
    // Channels-last: each pixel's dim/4 features are one contiguous row, which FeaturesAt gathers.
    maps.level[k] =
        torch::selu(Conv(x[k].contiguous(torch::MemoryFormat::ChannelsLast), "conv" + std::to_string(k + 1), 0))
            .contiguous(torch::MemoryFormat::ChannelsLast);
  }

  // The score head starts with a 1x1 convolution of the upsampled concatenation. Upsampling is linear per
  // channel, so the convolution is applied to each level first and only its 8 channels are upsampled
  // (upstream upsamples dim/4 channels per level to full size).
  const std::vector<int64_t> full{maps.padded_height, maps.padded_width};
  auto head = torch::conv2d(maps.level[0], W("score_head.0.level0"));
  for (int k = 1; k < 4; ++k) {
    auto part = torch::conv2d(maps.level[k], W("score_head.0.level" + std::to_string(k)));
    head.add_(torch::upsample_bilinear2d(part.contiguous(torch::MemoryFormat::ChannelsLast), full,
                                         /*align_corners=*/true));
  }
  head = torch::selu(head);
  head = torch::selu(Conv(head, "score_head.2", 1));
  head = torch::selu(Conv(head, "score_head.4", 1));
  auto score = Conv(head, "score_head.6", 1).sigmoid_();
  maps.score_map = score.slice(2, maps.pad_top, maps.pad_top + maps.height)
                       .slice(3, maps.pad_left, maps.pad_left + maps.width)
                       .contiguous();
  return maps;
}

torch::Tensor AlikedModel::DenseFeatureMap(const AlikedDenseMaps& maps) const {
  torch::InferenceMode guard;
  std::vector<torch::Tensor> parts;
  for (int k = 0; k < 4; ++k) {
    parts.push_back(k == 0 ? maps.level[0]
                           : torch::upsample_bilinear2d(maps.level[k], {maps.padded_height, maps.padded_width},
                                                        /*align_corners=*/true));
  }
  auto features = F::normalize(torch::cat(parts, 1), F::NormalizeFuncOptions().p(2).dim(1));
  return features.slice(2, maps.pad_top, maps.pad_top + maps.height)
      .slice(3, maps.pad_left, maps.pad_left + maps.width)
      .contiguous();
}

torch::Tensor AlikedModel::FeaturesAt(const AlikedDenseMaps& maps, const torch::Tensor& rows,
                                      const torch::Tensor& cols) const {
  torch::InferenceMode guard;
  const auto padded_rows = rows + maps.pad_top;
  const auto padded_cols = cols + maps.pad_left;
  std::vector<torch::Tensor> parts;
  for (int k = 0; k < 4; ++k) {
    const auto& level = maps.level[k];
    const int64_t h = level.size(2), w = level.size(3);
    // (h*w, C): the channels-last level seen as one row per pixel (no copy).
    const auto pixels = level.permute({0, 2, 3, 1}).reshape({h * w, level.size(1)});
    auto at = [&](const torch::Tensor& r, const torch::Tensor& c) { return pixels.index_select(0, r * w + c); };
    if (k == 0) {
      parts.push_back(at(padded_rows, padded_cols));
      continue;
    }
    const auto ty = UpsampleTaps(padded_rows, h, maps.padded_height);
    const auto tx = UpsampleTaps(padded_cols, w, maps.padded_width);
    const auto wx0 = tx.weight0.unsqueeze(1), wx1 = tx.weight1.unsqueeze(1);
    // The order of LibTorch's CPU kernel: interpolate along x on both rows, then along y.
    auto top = at(ty.index0, tx.index0).mul_(wx0).add_(at(ty.index0, tx.index1).mul_(wx1));
    auto bottom = at(ty.index1, tx.index0).mul_(wx0).add_(at(ty.index1, tx.index1).mul_(wx1));
    parts.push_back(top.mul_(ty.weight0.unsqueeze(1)).add_(bottom.mul_(ty.weight1.unsqueeze(1))));
  }
  return F::normalize(torch::cat(parts, 1), F::NormalizeFuncOptions().p(2).dim(1));
}

AlikedDescriptors AlikedModel::Describe(const AlikedDenseMaps& maps, const torch::Tensor& keypoints_in) const {
  torch::InferenceMode guard;
  const int64_t n = keypoints_in.size(0), height = maps.height, width = maps.width;
  const int64_t dim = config_.dim, samples = config_.num_samples, kernel = config_.kernel;
  AlikedDescriptors out;
  if (n == 0) {
    out.descriptors = torch::zeros({0, dim}, torch::TensorOptions().device(device_));
    out.offsets = torch::zeros({0, samples, 2}, torch::TensorOptions().device(device_));
    return out;
  }
  const auto keypoints = keypoints_in.to(device_, torch::kFloat32);
  const auto float_options = keypoints.options();
  const auto long_options = float_options.dtype(torch::kLong);
  auto wh = torch::tensor({float(width - 1), float(height - 1)}, float_options);
  // Keypoint pixels from the normalised coordinates, with upstream's arithmetic (it matters for the patch
  // position, which truncates).
  auto keypoints_px = (keypoints / 2 + 0.5) * wh;

  // The K x K patch of the feature map at the truncated keypoint position (zero outside the map), as
  // upstream's get_patches op.
  auto corner = keypoints_px.to(torch::kLong) - (kernel - 1) / 2;
  auto tap = torch::arange(kernel, long_options);
  auto patch_rows = (corner.select(1, 1).view({-1, 1, 1}) + tap.view({1, -1, 1})).expand({n, kernel, kernel});
  auto patch_cols = (corner.select(1, 0).view({-1, 1, 1}) + tap.view({1, 1, -1})).expand({n, kernel, kernel});
  auto patch_inside = (patch_rows >= 0)
                          .logical_and(patch_rows < height)
                          .logical_and(patch_cols >= 0)
                          .logical_and(patch_cols < width)
                          .reshape({-1, 1});
  auto patch =
      FeaturesAt(maps, patch_rows.clamp(0, height - 1).reshape({-1}), patch_cols.clamp(0, width - 1).reshape({-1}));
  patch = patch.mul_(patch_inside.to(torch::kFloat32));  // (n*K*K, dim)
  patch = patch.view({n, kernel * kernel, dim}).transpose(1, 2).reshape({n, dim * kernel * kernel});

  // Offsets: conv KxK (no padding) -> selu -> conv 1x1, on the patch, clamped as upstream.
  auto offsets =
      torch::selu(torch::addmm(W("desc_head.offset_conv.0.bias"), patch, W("desc_head.offset_conv.0.matrix")));
  offsets = torch::addmm(W("desc_head.offset_conv.2.bias"), offsets, W("desc_head.offset_conv.2.matrix"));
  const double max_offset = double(std::max(height, width)) / 4.0;
  offsets = offsets.clamp_(-max_offset, max_offset).view({n, 2, samples}).transpose(1, 2);  // (n, M, 2) as (x, y)
  out.offsets = offsets.contiguous();

  // Sample positions, normalised and un-normalised again as grid_sample(align_corners=True) does upstream.
  auto position = keypoints_px.unsqueeze(1) + offsets;
  auto normalised = 2.0 * position / wh - 1;
  auto half_extent = torch::tensor({float(width - 1) / 2.f, float(height - 1) / 2.f}, float_options);
  auto sample = ((normalised + 1) * half_extent).reshape({-1, 2});
  auto sx = sample.select(1, 0), sy = sample.select(1, 1);
  auto x0 = sx.floor(), y0 = sy.floor();
  auto east = sx - x0, south = sy - y0;
  auto west = 1 - east, north = 1 - south;
  // Bilinear with zero padding: each corner reads the feature map where it lies inside.
  auto corner_value = [&](const torch::Tensor& r, const torch::Tensor& c) {
    auto inside = (r >= 0).logical_and(r < height).logical_and(c >= 0).logical_and(c < width);
    auto values = FeaturesAt(maps, r.clamp(0, height - 1).to(torch::kLong), c.clamp(0, width - 1).to(torch::kLong));
    return values.mul_(inside.to(torch::kFloat32).unsqueeze(1));
  };
  auto features = corner_value(y0, x0).mul_((north * west).unsqueeze(1));
  features.add_(corner_value(y0, x0 + 1).mul_((north * east).unsqueeze(1)));
  features.add_(corner_value(y0 + 1, x0).mul_((south * west).unsqueeze(1)));
  features.add_(corner_value(y0 + 1, x0 + 1).mul_((south * east).unsqueeze(1)));  // (n*M, dim)

  // sf_conv (1x1) -> selu, then each sample's features through its own dim x dim matrix, summed.
  features = torch::selu(features.mm(W("desc_head.sf_conv.matrix")));
  auto descriptors = features.view({n, samples * dim}).mm(W("desc_head.agg_matrix"));
  out.descriptors = F::normalize(descriptors, F::NormalizeFuncOptions().p(2).dim(1));
  return out;
}

}  // namespace vmap::neural
