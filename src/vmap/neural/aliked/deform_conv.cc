#include "vmap/neural/aliked/deform_conv.h"

#include <stdexcept>

namespace vmap::neural {

namespace {

// Deformable im2col of one image (C, H, W), channels last: (Ho*Wo, K*K*C), column t*C + c for tap t and
// channel c. Each bilinear corner is one row gather from the zero-bordered image seen as (pixels, C).
torch::Tensor DeformableColumns(const torch::Tensor& image, const torch::Tensor& offset, const torch::Tensor& mask,
                                int64_t kernel, int64_t padding) {
  const int64_t channels = image.size(0), height = image.size(1), width = image.size(2);
  const int64_t out_h = offset.size(1), out_w = offset.size(2);
  const int64_t taps = kernel * kernel;
  const auto float_options = offset.options();

  // Sample positions of every (output pixel, tap): (Ho, Wo, taps).
  auto tap = torch::arange(taps, float_options);
  auto tap_row = torch::floor(tap / double(kernel));
  auto tap_col = tap - tap_row * double(kernel);
  auto out_row = torch::arange(out_h, float_options).sub_(double(padding));
  auto out_col = torch::arange(out_w, float_options).sub_(double(padding));
  auto offsets = offset.view({taps, 2, out_h, out_w}).permute({2, 3, 0, 1});  // (Ho, Wo, taps, 2)
  auto y = (out_row.view({out_h, 1, 1}) + tap_row.view({1, 1, taps})) + offsets.select(3, 0);
  auto x = (out_col.view({1, out_w, 1}) + tap_col.view({1, 1, taps})) + offsets.select(3, 1);

  // A sample contributes only strictly inside (-1, H) x (-1, W); its corners outside the image read the zero
  // border of `bordered`, so every index below stays in range.
  auto inside = (y > -1.0).logical_and_(y < double(height)).logical_and_(x > -1.0).logical_and_(x < double(width));
  auto y0 = torch::floor(y);
  auto x0 = torch::floor(x);
  auto ly = y - y0, lx = x - x0;
  auto hy = 1.0 - ly, hx = 1.0 - lx;
  auto gate = inside.to(float_options.dtype());
  if (mask.defined()) gate = gate * mask.view({taps, out_h, out_w}).permute({1, 2, 0});
  // Bordered coordinates: image pixel (r, c) is at (r + 1, c + 1); outside samples are moved to (0, 0).
  auto row0 = (y0 + 1.0).clamp_(0.0, double(height)).to(torch::kLong);
  auto col0 = (x0 + 1.0).clamp_(0.0, double(width)).to(torch::kLong);
  const int64_t stride = width + 2;
  auto index00 = (row0 * stride + col0).reshape({-1});
  auto index01 = index00 + 1;
  auto index10 = index00 + stride;
  auto index11 = index10 + 1;

  auto bordered = torch::constant_pad_nd(image.permute({1, 2, 0}), {0, 0, 1, 1, 1, 1}, 0.0).reshape({-1, channels});
  auto w00 = (hy * hx * gate).reshape({-1, 1}), w01 = (hy * lx * gate).reshape({-1, 1});
  auto w10 = (ly * hx * gate).reshape({-1, 1}), w11 = (ly * lx * gate).reshape({-1, 1});
  auto columns = bordered.index_select(0, index00).mul_(w00);
  columns.addcmul_(bordered.index_select(0, index01), w01);
  columns.addcmul_(bordered.index_select(0, index10), w10);
  columns.addcmul_(bordered.index_select(0, index11), w11);
  return columns.view({out_h * out_w, taps * channels});
}

}  // namespace

torch::Tensor DeformConv2d(const torch::Tensor& input, const torch::Tensor& offset, const torch::Tensor& weight,
                           const torch::Tensor& bias, const torch::Tensor& mask, int64_t padding) {
  if (input.dim() != 4 || weight.dim() != 4 || offset.dim() != 4 || weight.size(2) != weight.size(3) ||
      weight.size(1) != input.size(1)) {
    throw std::invalid_argument("DeformConv2d: expected input (B,C,H,W), weight (O,C,K,K), offset (B,2KK,Ho,Wo)");
  }
  const int64_t batch = input.size(0), kernel = weight.size(2), out_channels = weight.size(0);
  const int64_t out_h = input.size(2) + 2 * padding - kernel + 1;
  const int64_t out_w = input.size(3) + 2 * padding - kernel + 1;
  if (offset.size(0) != batch || offset.size(1) != 2 * kernel * kernel || offset.size(2) != out_h ||
      offset.size(3) != out_w) {
    throw std::invalid_argument("DeformConv2d: offset must be (B, 2*K*K, Ho, Wo)");
  }
  if (mask.defined() && (mask.dim() != 4 || mask.size(0) != batch || mask.size(1) != kernel * kernel ||
                         mask.size(2) != out_h || mask.size(3) != out_w)) {
    throw std::invalid_argument("DeformConv2d: mask must be (B, K*K, Ho, Wo)");
  }
  // (K*K*C, O), rows in the columns' tap-major order.
  const auto flat_weight = weight.permute({2, 3, 1, 0}).reshape({-1, out_channels});
  std::vector<torch::Tensor> outputs;
  for (int64_t b = 0; b < batch; ++b) {
    auto columns = DeformableColumns(input[b], offset[b].contiguous(), mask.defined() ? mask[b] : torch::Tensor(),
                                     kernel, padding);
    auto out = bias.defined() ? torch::addmm(bias, columns, flat_weight) : columns.mm(flat_weight);  // (Ho*Wo, O)
    outputs.push_back(out.view({1, out_h, out_w, out_channels}).permute({0, 3, 1, 2}));
  }
  // Channels-last, as the matrix product leaves it.
  return batch == 1 ? outputs[0] : torch::cat(outputs, 0);
}

}  // namespace vmap::neural
