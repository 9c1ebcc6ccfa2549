#include "vmap/neural/loftr/loftr_model.h"

#include <cmath>
#include <stdexcept>

namespace vmap::neural {

namespace F = torch::nn::functional;
using torch::indexing::None;
using torch::indexing::Slice;

namespace {

constexpr double kBatchNormEps = 1e-5;    // PyTorch's BatchNorm2d default, used by every LoFTR backbone
constexpr double kLeakyReluSlope = 0.01;  // PyTorch's LeakyReLU default, used in the FPN merges

torch::Tensor Upsample2x(const torch::Tensor& x) {
  return torch::upsample_bilinear2d(x, {2 * x.size(2), 2 * x.size(3)}, /*align_corners=*/true);
}

// elu(x) + 1 keeps attention weights positive, which linear attention needs for its normaliser.
torch::Tensor PositiveFeatureMap(const torch::Tensor& x) { return torch::elu(x).add_(1.0); }

// Linear attention: softmax(QK^T)V is replaced by phi(Q) (phi(K)^T V), which is linear in sequence length.
// q: (N, L, H, D), k and v: (N, S, H, D); returns (N, L, H, D).
torch::Tensor LinearAttention(const torch::Tensor& q, const torch::Tensor& k, const torch::Tensor& v, double eps) {
  const double length = static_cast<double>(v.size(1));
  auto Q = PositiveFeatureMap(q).permute({0, 2, 1, 3});  // (N, H, L, D)
  auto K = PositiveFeatureMap(k).permute({0, 2, 1, 3});  // (N, H, S, D)
  // Dividing V by the length before the product (and multiplying back after) keeps K^T V in float range
  // for long sequences, as the reference does; the result is unchanged up to rounding.
  auto V = (v / length).permute({0, 2, 1, 3});                        // (N, H, S, D)
  auto kv = torch::matmul(K.transpose(2, 3), V);                      // (N, H, D, D)
  auto k_sum = K.sum(2).unsqueeze(-1);                                // (N, H, D, 1)
  auto normaliser = torch::matmul(Q, k_sum).add_(eps).reciprocal_();  // (N, H, L, 1)
  auto out = torch::matmul(Q, kv).mul_(normaliser).mul_(length);      // (N, H, L, D)
  return out.permute({0, 2, 1, 3});
}

}  // namespace

LoftrModel::LoftrModel(LoftrConfig config, const StateDict& weights, torch::Device device)
    : config_(std::move(config)), device_(device), threshold_(config_.threshold) {
  torch::InferenceMode guard;
  for (const auto& [key, tensor] : weights) {
    auto converted = tensor.is_floating_point() ? tensor.to(torch::kFloat32) : tensor;
    weights_[key] = converted.to(device_).contiguous();
  }
  for (const auto& spec : ExpectedStateDict(config_)) {
    if (!weights_.count(spec.key)) throw std::invalid_argument("LoftrModel: missing weight " + spec.key);
  }
}

const torch::Tensor& LoftrModel::W(const std::string& key) const {
  auto it = weights_.find(key);
  if (it == weights_.end()) throw std::invalid_argument("LoftrModel: missing weight " + key);
  return it->second;
}

torch::Tensor LoftrModel::BatchNorm(const torch::Tensor& x, const std::string& bn) const {
  return torch::batch_norm(x, W(bn + ".weight"), W(bn + ".bias"), W(bn + ".running_mean"), W(bn + ".running_var"),
                           /*training=*/false, /*momentum=*/0.0, kBatchNormEps, /*cudnn_enabled=*/true);
}

torch::Tensor LoftrModel::ConvBn(const torch::Tensor& x, const std::string& conv, const std::string& bn, int64_t stride,
                                 int64_t padding) const {
  return BatchNorm(torch::conv2d(x, W(conv), {}, stride, padding), bn);
}

torch::Tensor LoftrModel::ResidualBlock(const torch::Tensor& x, const std::string& p, bool has_projection,
                                        int64_t stride) const {
  auto y = ConvBn(x, p + ".conv1.weight", p + ".bn1", stride, 1).relu_();
  y = ConvBn(y, p + ".conv2.weight", p + ".bn2", 1, 1);
  auto shortcut = has_projection ? ConvBn(x, p + ".downsample.0.weight", p + ".downsample.1", stride, 0) : x;
  return y.add_(shortcut).relu_();
}

torch::Tensor LoftrModel::PositionalEncoding(int64_t coarse_h, int64_t coarse_w) const {
  torch::InferenceMode guard;
  const int64_t d = config_.d_model;
  const double log_base = -std::log(10000.0);
  // The reference's buggy variant divides by d and then floor-divides by 2 (Python precedence), giving -1.
  const double exponent_scale = config_.temp_bug_fix ? log_base / static_cast<double>(d / 2)
                                                     : std::floor(log_base / static_cast<double>(d) / 2.0);
  auto opts = torch::TensorOptions().dtype(torch::kFloat32);
  auto frequencies = torch::exp(torch::arange(0, d / 2, 2, opts) * exponent_scale).view({-1, 1, 1});
  // Positions count from 1, as a cumulative sum of ones does upstream.
  auto ones = torch::ones({coarse_h, coarse_w}, opts);
  auto y_position = ones.cumsum(0).unsqueeze(0);
  auto x_position = ones.cumsum(1).unsqueeze(0);
  auto pe = torch::zeros({d, coarse_h, coarse_w}, opts);
  pe.index_put_({Slice(0, None, 4)}, torch::sin(x_position * frequencies));
  pe.index_put_({Slice(1, None, 4)}, torch::cos(x_position * frequencies));
  pe.index_put_({Slice(2, None, 4)}, torch::sin(y_position * frequencies));
  pe.index_put_({Slice(3, None, 4)}, torch::cos(y_position * frequencies));
  return pe.unsqueeze(0).to(device_);
}

LoftrImageFeatures LoftrModel::Extract(const torch::Tensor& image_in) const {
  torch::InferenceMode guard;
  const int64_t stride = config_.coarse_stride;
  auto image = image_in.to(device_);
  if (image.dim() != 4 || image.size(0) != 1 || image.size(1) != 1 || image.size(2) % stride != 0 ||
      image.size(3) % stride != 0 || image.size(2) == 0 || image.size(3) == 0) {
    throw std::invalid_argument("LoftrModel::Extract: expected (1,1,H,W) with H, W positive multiples of " +
                                std::to_string(stride));
  }
  LoftrImageFeatures out;
  out.height = image.size(2);
  out.width = image.size(3);

  auto x0 = ConvBn(image, "backbone.conv1.weight", "backbone.bn1", 2, 3).relu_();
  std::vector<torch::Tensor> levels{x0};  // levels[k] is at 1/2^k of the input
  const auto& dims = config_.block_dims;
  int64_t in_dim = config_.initial_dim;
  for (size_t stage = 0; stage < dims.size(); ++stage) {
    const std::string p = "backbone.layer" + std::to_string(stage + 1);
    const int64_t s = stage == 0 ? 1 : 2;
    auto x = ResidualBlock(levels.back(), p + ".0", s != 1 || in_dim != dims[stage], s);
    x = ResidualBlock(x, p + ".1", false, 1);
    if (stage == 0)
      levels.back() = x;
    else
      levels.push_back(x);
    in_dim = dims[stage];
  }
  // levels: [layer1 (1/2), layer2 (1/4), layer3 (1/8), (layer4 (1/16))]
  const int deepest = static_cast<int>(dims.size());
  auto top = torch::conv2d(levels.back(), W("backbone.layer" + std::to_string(deepest) + "_outconv.weight"));
  out.coarse_backbone = top;
  if (config_.has_fine) {
    // Top-down path to the fine level; the coarse student never uses its finer map, so it skips this.
    const int finest = config_.backbone == BackboneKind::kResNetFpn8_2 ? 1 : 2;
    auto merged = top;
    for (int level = deepest - 1; level >= finest; --level) {
      const std::string p = "backbone.layer" + std::to_string(level);
      auto lateral = torch::conv2d(levels[level - 1], W(p + "_outconv.weight"));
      auto y = lateral.add_(Upsample2x(merged));
      y = ConvBn(y, p + "_outconv2.0.weight", p + "_outconv2.1", 1, 1);
      y = torch::leaky_relu(y, kLeakyReluSlope);
      merged = torch::conv2d(y, W(p + "_outconv2.3.weight"), {}, 1, 1);
    }
    out.fine = merged;
  }
  out.coarse_h = top.size(2);
  out.coarse_w = top.size(3);
  auto with_pe = top + PositionalEncoding(out.coarse_h, out.coarse_w);
  out.coarse = with_pe.flatten(2).transpose(1, 2).contiguous();  // (1, L, C)
  return out;
}

torch::Tensor LoftrModel::EncoderLayer(const torch::Tensor& x, const torch::Tensor& source, const std::string& p,
                                       int64_t nhead, double norm_eps) const {
  const int64_t batch = x.size(0), d = x.size(2), head_dim = d / nhead;
  auto q = torch::linear(x, W(p + ".q_proj.weight")).view({batch, -1, nhead, head_dim});
  auto k = torch::linear(source, W(p + ".k_proj.weight")).view({batch, -1, nhead, head_dim});
  auto v = torch::linear(source, W(p + ".v_proj.weight")).view({batch, -1, nhead, head_dim});
  auto message = LinearAttention(q, k, v, config_.attention_eps).reshape({batch, -1, d});
  message = torch::linear(message, W(p + ".merge.weight"));
  message = torch::layer_norm(message, {d}, W(p + ".norm1.weight"), W(p + ".norm1.bias"), norm_eps);
  message = torch::linear(torch::cat({x, message}, 2), W(p + ".mlp.0.weight")).relu_();
  message = torch::linear(message, W(p + ".mlp.2.weight"));
  message = torch::layer_norm(message, {d}, W(p + ".norm2.weight"), W(p + ".norm2.bias"), norm_eps);
  return message.add_(x);
}

void LoftrModel::Transformer(torch::Tensor& feat0, torch::Tensor& feat1, const std::string& prefix, int num_pairs,
                             int64_t nhead, double norm_eps) const {
  for (int pair = 0; pair < num_pairs; ++pair) {
    const std::string self_layer = prefix + ".layers." + std::to_string(2 * pair);
    const std::string cross_layer = prefix + ".layers." + std::to_string(2 * pair + 1);
    feat0 = EncoderLayer(feat0, feat0, self_layer, nhead, norm_eps);
    feat1 = EncoderLayer(feat1, feat1, self_layer, nhead, norm_eps);
    // Image 1 attends to the already updated image 0, as the reference does.
    feat0 = EncoderLayer(feat0, feat1, cross_layer, nhead, norm_eps);
    feat1 = EncoderLayer(feat1, feat0, cross_layer, nhead, norm_eps);
  }
}

LoftrPairOutput LoftrModel::Match(const LoftrImageFeatures& image0, const LoftrImageFeatures& image1,
                                  bool keep_conf) const {
  torch::InferenceMode guard;
  LoftrPairOutput out;
  auto feat0 = image0.coarse, feat1 = image1.coarse;
  Transformer(feat0, feat1, "loftr_coarse", config_.num_coarse_layer_pairs, config_.nhead, config_.layer_norm_eps);
  out.feat_c0 = feat0;
  out.feat_c1 = feat1;

  // Dual softmax over the scaled similarity.
  const double feature_scale = std::sqrt(static_cast<double>(feat0.size(2)));
  auto sim = torch::matmul(feat0 / feature_scale, (feat1 / feature_scale).transpose(1, 2)).div_(config_.temperature);
  auto conf = torch::softmax(sim, 1);
  conf.mul_(torch::softmax(sim, 2));
  sim = torch::Tensor();
  if (keep_conf) out.conf = conf;

  auto row = conf[0].max(1);
  auto col = conf[0].max(0);
  out.row_max = std::get<0>(row);
  out.row_argmax = std::get<1>(row);
  out.col_max = std::get<0>(col);
  out.col_argmax = std::get<1>(col);
  conf = torch::Tensor();

  // A match is a mutual nearest neighbour above the threshold, away from both images' borders.
  auto inside_border = [&](int64_t h, int64_t w) {
    const int64_t b = config_.border_removal;
    auto opts = torch::TensorOptions().dtype(torch::kBool).device(device_);
    auto mask = torch::ones({h, w}, opts);
    if (b > 0) {
      mask.index_put_({Slice(0, b)}, false);
      mask.index_put_({Slice(h - b, None)}, false);
      mask.index_put_({Slice(), Slice(0, b)}, false);
      mask.index_put_({Slice(), Slice(w - b, None)}, false);
    }
    return mask.flatten();
  };
  auto valid = out.row_max.gt(threshold_)
                   .logical_and_(out.col_max.index_select(0, out.row_argmax).eq(out.row_max))
                   .logical_and_(inside_border(image0.coarse_h, image0.coarse_w))
                   .logical_and_(inside_border(image1.coarse_h, image1.coarse_w).index_select(0, out.row_argmax));
  out.i_ids = valid.nonzero().flatten();
  out.j_ids = out.row_argmax.index_select(0, out.i_ids);
  out.mconf = out.row_max.index_select(0, out.i_ids);
  auto cell_corner = [](const torch::Tensor& ids, int64_t coarse_w, double scale) {
    return torch::stack({ids.remainder(coarse_w), ids.div(coarse_w, "floor")}, 1) * scale;
  };
  out.mkpts0_c = cell_corner(out.i_ids, image0.coarse_w,
                             static_cast<double>(image0.height) / static_cast<double>(image0.coarse_h));
  out.mkpts1_c = cell_corner(out.j_ids, image1.coarse_w,
                             static_cast<double>(image1.height) / static_cast<double>(image1.coarse_h));
  if (config_.has_fine) FineStage(image0, image1, out);
  return out;
}

void LoftrModel::FineStage(const LoftrImageFeatures& image0, const LoftrImageFeatures& image1,
                           LoftrPairOutput& out) const {
  const int64_t window = config_.fine_window, ww = window * window, pad = window / 2;
  const int64_t channels = config_.fine_d_model;
  const int64_t num_matches = out.i_ids.size(0);
  auto float_opts = torch::TensorOptions().dtype(torch::kFloat32).device(device_);
  if (num_matches == 0) {
    out.fine_pre0 = out.fine_pre1 = out.fine0 = out.fine1 = torch::empty({0, ww, channels}, float_opts);
    out.expec_f = torch::empty({0, 3}, float_opts);
    out.mkpts0_f = out.mkpts0_c;
    out.mkpts1_f = out.mkpts1_c;
    return;
  }
  // The window of each coarse cell on the fine map: window x window fine pixels centred on the cell's
  // top-left fine pixel, zero outside the map (as a strided unfold with padding window/2 gives).
  auto gather_windows = [&](const LoftrImageFeatures& image, const torch::Tensor& ids) {
    const int64_t step = image.fine.size(2) / image.coarse_h;
    auto padded = torch::constant_pad_nd(image.fine[0], {pad, pad, pad, pad});  // (Cf, hf+2p, wf+2p)
    const int64_t padded_w = padded.size(2);
    auto y = ids.div(image.coarse_w, "floor") * step;
    auto x = ids.remainder(image.coarse_w) * step;
    auto offsets = torch::arange(window, ids.options()).unsqueeze(1) * padded_w +
                   torch::arange(window, ids.options()).unsqueeze(0);
    auto flat_ids = ((y * padded_w + x).unsqueeze(1) + offsets.flatten().unsqueeze(0)).flatten();
    return padded.flatten(1).index_select(1, flat_ids).t().reshape({-1, ww, padded.size(0)});
  };
  auto win0 = gather_windows(image0, out.i_ids);
  auto win1 = gather_windows(image1, out.j_ids);
  auto windows = torch::cat({win0, win1}, 0);  // (2M, ww, Cf)
  if (config_.fine_concat_coarse_feat) {
    auto coarse = torch::cat({out.feat_c0[0].index_select(0, out.i_ids), out.feat_c1[0].index_select(0, out.j_ids)});
    auto projected = torch::linear(coarse, W("fine_preprocess.down_proj.weight"), W("fine_preprocess.down_proj.bias"));
    windows = torch::linear(torch::cat({windows, projected.unsqueeze(1).expand({-1, ww, -1})}, 2),
                            W("fine_preprocess.merge_feat.weight"), W("fine_preprocess.merge_feat.bias"));
  }
  auto halves = windows.chunk(2, 0);
  out.fine_pre0 = halves[0];
  out.fine_pre1 = halves[1];
  auto fine0 = halves[0].contiguous(), fine1 = halves[1].contiguous();
  Transformer(fine0, fine1, "loftr_fine", config_.num_fine_layer_pairs, config_.fine_nhead, config_.layer_norm_eps);
  out.fine0 = fine0;
  out.fine1 = fine1;

  // Where image 0's window centre lands in image 1's window: the expectation of a softmax heatmap.
  auto centre = fine0.select(1, ww / 2);                            // (M, C)
  auto sim = torch::matmul(fine1, centre.unsqueeze(2)).squeeze(2);  // (M, ww)
  auto heatmap = torch::softmax(sim * (1.0 / std::sqrt(static_cast<double>(channels))), 1);
  auto axis = torch::linspace(-1.0, 1.0, window, float_opts);
  auto grid_x = axis.repeat({window});  // column-fastest, x = column
  auto grid_y = axis.repeat_interleave(window);
  auto grid = torch::stack({grid_x, grid_y}, 1);  // (ww, 2)
  auto coords = torch::matmul(heatmap, grid);     // (M, 2)
  auto variance = torch::matmul(heatmap, grid * grid) - coords * coords;
  auto spread = variance.clamp_min(1e-10).sqrt().sum(1, true);
  out.expec_f = torch::cat({coords, spread}, 1);
  const double fine_scale = static_cast<double>(image1.height) / static_cast<double>(image1.fine.size(2));
  out.mkpts0_f = out.mkpts0_c;
  out.mkpts1_f = out.mkpts1_c + coords * static_cast<double>(window / 2) * fine_scale;
}

}  // namespace vmap::neural
