#pragma once
// Deformable convolution (Dai et al. 2017; with the modulation mask of DCNv2, Zhu et al. 2019) on LibTorch ops,
// with the semantics of torchvision.ops.deform_conv2d, which LibTorch's C++ API does not have.
// Includes LibTorch: internal to vmap/neural.

#include <torch/torch.h>

namespace vmap::neural {

// `input` (B, C, H, W); `offset` (B, 2*K*K, Ho, Wo) holding, for kernel tap t = i*K + j, the row offset in
// channel 2t and the column offset in channel 2t+1 (torchvision's layout); `weight` (O, C, K, K); `bias` (O)
// or undefined; `mask` (B, K*K, Ho, Wo) or undefined (then every tap has weight 1, as DCNv1). Stride 1,
// dilation 1, one offset group. Tap t of output pixel (y, x) reads the input bilinearly at
// (y - padding + i + dy, x - padding + j + dx), with zeros outside the image (a sample at or beyond one pixel
// outside reads 0). Works on any device.
//
// Implementation: the bilinear samples of all taps are gathered into one channels-last column matrix
// (Ho*Wo, K*K*C): four row gathers from a zero-bordered copy of the input and their weighted sum; one matrix
// product with the weights gives the output, returned channels-last (B, O, Ho, Wo). On this project's CPU the
// gather + product took less CPU time than one grid_sample per tap followed by the same product
// (bench/aliked_bench --dcn); the product itself is most of the cost, so a hand-written kernel for the gather
// would gain little (docs/measurements/code-choices.md, "ALIKED on the CPU").
torch::Tensor DeformConv2d(const torch::Tensor& input, const torch::Tensor& offset, const torch::Tensor& weight,
                           const torch::Tensor& bias, const torch::Tensor& mask, int64_t padding);

}  // namespace vmap::neural
