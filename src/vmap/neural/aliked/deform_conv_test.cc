// DeformConv2d against a direct, one-sample-at-a-time evaluation of torchvision's definition.

#include "vmap/neural/aliked/deform_conv.h"

#include <cmath>

#include <gtest/gtest.h>

namespace vmap::neural {
namespace {

// torchvision's bilinear read: 0 at or beyond one pixel outside, corners outside the image read 0.
float Bilinear(const torch::Tensor& plane, double y, double x) {
  const int64_t h = plane.size(0), w = plane.size(1);
  if (y <= -1 || y >= h || x <= -1 || x >= w) return 0.f;
  const auto a = plane.accessor<float, 2>();
  const int64_t y0 = static_cast<int64_t>(std::floor(y)), x0 = static_cast<int64_t>(std::floor(x));
  const double ly = y - y0, lx = x - x0;
  auto at = [&](int64_t r, int64_t c) { return (r >= 0 && r < h && c >= 0 && c < w) ? double(a[r][c]) : 0.0; };
  return static_cast<float>((1 - ly) * (1 - lx) * at(y0, x0) + (1 - ly) * lx * at(y0, x0 + 1) +
                            ly * (1 - lx) * at(y0 + 1, x0) + ly * lx * at(y0 + 1, x0 + 1));
}

torch::Tensor Reference(const torch::Tensor& input, const torch::Tensor& offset, const torch::Tensor& weight,
                        const torch::Tensor& bias, const torch::Tensor& mask, int64_t padding) {
  const int64_t batch = input.size(0), channels = input.size(1), out_channels = weight.size(0);
  const int64_t k = weight.size(2), out_h = offset.size(2), out_w = offset.size(3);
  auto out = torch::zeros({batch, out_channels, out_h, out_w});
  auto o = out.accessor<float, 4>();
  const auto off = offset.accessor<float, 4>();
  const auto wt = weight.accessor<float, 4>();
  for (int64_t b = 0; b < batch; ++b) {
    for (int64_t y = 0; y < out_h; ++y) {
      for (int64_t x = 0; x < out_w; ++x) {
        for (int64_t i = 0; i < k; ++i) {
          for (int64_t j = 0; j < k; ++j) {
            const int64_t t = i * k + j;
            const double sy = y - padding + i + off[b][2 * t][y][x];
            const double sx = x - padding + j + off[b][2 * t + 1][y][x];
            const double m = mask.defined() ? mask[b][t][y][x].item<float>() : 1.0;
            for (int64_t c = 0; c < channels; ++c) {
              const double v = m * Bilinear(input[b][c], sy, sx);
              for (int64_t oc = 0; oc < out_channels; ++oc) o[b][oc][y][x] += float(wt[oc][c][i][j] * v);
            }
          }
        }
        if (bias.defined()) {
          for (int64_t oc = 0; oc < out_channels; ++oc) o[b][oc][y][x] += bias[oc].item<float>();
        }
      }
    }
  }
  return out;
}

class DeformConvTest : public ::testing::Test {
 protected:
  void SetUp() override { torch::manual_seed(7); }
};

TEST_F(DeformConvTest, ZeroOffsetsAreAPlainConvolution) {
  torch::NoGradGuard no_grad;
  auto input = torch::randn({1, 5, 9, 11});
  auto weight = torch::randn({4, 5, 3, 3});
  auto bias = torch::randn({4});
  for (int64_t padding : {0, 1}) {
    const int64_t out_h = 9 + 2 * padding - 2, out_w = 11 + 2 * padding - 2;
    auto offset = torch::zeros({1, 18, out_h, out_w});
    auto ours = DeformConv2d(input, offset, weight, bias, torch::Tensor(), padding);
    auto plain = torch::conv2d(input, weight, bias, 1, padding);
    EXPECT_TRUE(torch::allclose(ours, plain, 1e-5, 1e-5)) << (ours - plain).abs().max().item<float>();
  }
}

TEST_F(DeformConvTest, IntegerOffsetsShiftTheInput) {
  torch::NoGradGuard no_grad;
  auto input = torch::randn({1, 3, 8, 8});
  auto weight = torch::randn({2, 3, 3, 3});
  auto offset = torch::zeros({1, 18, 8, 8});
  offset.select(1, 0).fill_(2.0);    // tap 0 reads two rows lower
  offset.select(1, 17).fill_(-1.0);  // tap 8 reads one column to the left
  auto ours = DeformConv2d(input, offset, weight, torch::Tensor(), torch::Tensor(), 1);
  EXPECT_TRUE(torch::allclose(ours, Reference(input, offset, weight, torch::Tensor(), torch::Tensor(), 1), 1e-5, 1e-5));
}

TEST_F(DeformConvTest, FractionalOffsetsAcrossTheBorderMatchTheDefinition) {
  torch::NoGradGuard no_grad;
  auto input = torch::randn({2, 4, 7, 10});
  auto weight = torch::randn({3, 4, 3, 3});
  auto bias = torch::randn({3});
  // Offsets up to 6 px reach well outside the 7x10 image: partial corners and fully outside samples.
  auto offset = (torch::rand({2, 18, 7, 10}) - 0.5) * 12.0;
  offset[0][0][0][0] = -1.0;  // a sample exactly one pixel outside reads 0
  offset[0][1][0][0] = 0.25;
  auto ours = DeformConv2d(input, offset, weight, bias, torch::Tensor(), 1);
  auto expected = Reference(input, offset, weight, bias, torch::Tensor(), 1);
  EXPECT_TRUE(torch::allclose(ours, expected, 1e-4, 1e-5)) << (ours - expected).abs().max().item<float>();
}

TEST_F(DeformConvTest, ModulationMaskWeightsEachTap) {
  torch::NoGradGuard no_grad;
  auto input = torch::randn({1, 4, 6, 6});
  auto weight = torch::randn({5, 4, 3, 3});
  auto offset = (torch::rand({1, 18, 6, 6}) - 0.5) * 4.0;
  auto mask = torch::rand({1, 9, 6, 6});
  auto ours = DeformConv2d(input, offset, weight, torch::Tensor(), mask, 1);
  auto expected = Reference(input, offset, weight, torch::Tensor(), mask, 1);
  EXPECT_TRUE(torch::allclose(ours, expected, 1e-4, 1e-5)) << (ours - expected).abs().max().item<float>();
  // A zero mask silences the layer; a mask of ones is DCNv1.
  EXPECT_EQ(DeformConv2d(input, offset, weight, torch::Tensor(), torch::zeros_like(mask), 1).abs().max().item<float>(),
            0.f);
  EXPECT_TRUE(torch::allclose(DeformConv2d(input, offset, weight, torch::Tensor(), torch::ones_like(mask), 1),
                              DeformConv2d(input, offset, weight, torch::Tensor(), torch::Tensor(), 1)));
}

TEST_F(DeformConvTest, RejectsInconsistentShapes) {
  auto input = torch::randn({1, 4, 6, 6});
  auto weight = torch::randn({5, 4, 3, 3});
  EXPECT_THROW(DeformConv2d(input, torch::zeros({1, 9, 6, 6}), weight, {}, {}, 1), std::invalid_argument);
  EXPECT_THROW(DeformConv2d(input, torch::zeros({1, 18, 5, 6}), weight, {}, {}, 1), std::invalid_argument);
  EXPECT_THROW(DeformConv2d(input, torch::zeros({1, 18, 6, 6}), torch::randn({5, 3, 3, 3}), {}, {}, 1),
               std::invalid_argument);
  EXPECT_THROW(DeformConv2d(input, torch::zeros({1, 18, 6, 6}), weight, {}, torch::zeros({1, 8, 6, 6}), 1),
               std::invalid_argument);
}

}  // namespace
}  // namespace vmap::neural
