#pragma once
// XFeat (Potje et al., CVPR 2024), the sparse path: the network and upstream's detectAndCompute, on LibTorch
// tensors (inference only). Internal to vmap/neural: this header includes LibTorch.
//
// ../shared/weights/xfeat/README.md describes the network layer by layer; ../shared/golden/README.md
// ("xfeat") the post-processing, which this port reproduces op for op (the same LibTorch kernels in the
// same order), so that the golden outputs are met bit for bit on the same machine.

#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <torch/torch.h>

#include "vmap/neural/state_dict.h"

namespace vmap::neural {

// One convolution of the network. `batch_norm` convolutions are the upstream BasicLayers (conv without
// bias, BatchNorm2d without affine parameters, ReLU), named "<name>.layer.0"; the others ("skip1.1",
// "block_fusion.2", "heatmap_head.2", "keypoint_head.3") have a bias and no BatchNorm or ReLU.
struct XfeatConv {
  std::string name;  // e.g. "block1.0" (BasicLayer) or "skip1.1"
  int64_t out_channels, in_channels, kernel, stride;
  bool batch_norm;
  std::string weight_key() const { return batch_norm ? name + ".layer.0.weight" : name + ".weight"; }
  std::string bias_key() const { return batch_norm ? name + ".layer.0.bias" : name + ".bias"; }
};
const std::vector<XfeatConv>& XfeatConvolutions();  // all 27, in upstream state_dict order

// The raw network outputs for an (B, C, H, W) input.
struct XfeatNetOutput {
  torch::Tensor descriptor_map;   // M1 (B, 64, H/8, W/8), not normalised
  torch::Tensor keypoint_logits;  // K1 (B, 65, H/8, W/8), channel 64 is the "no keypoint" bin
  torch::Tensor reliability;      // H1 (B, 1, H/8, W/8), after the sigmoid
};

struct XfeatDetectOptions {
  int64_t top_k = 4096;
  double detection_threshold = 0.05;
  bool keep_intermediates = false;  // fills the fields marked "intermediate" (for the golden tests)
  // A camera mask: CV_8UC1 of the image's size, 0 where no keypoint may be (KeptByMask, features/camera_mask.h). The
  // peaks outside it are dropped before the top_k best are taken, so the mask keeps the whole budget within it.
  // Empty: everywhere.
  cv::Mat keep;
  // On the CPU the network, the NMS and the descriptor sampling have faster equivalents of upstream's
  // LibTorch ops; these use upstream's ops (as on a GPU) instead, for tests that compare the two.
  bool upstream_network_ops = false;
  bool upstream_postprocessing_ops = false;
};

// detectAndCompute of one image. Keypoints are in descending score order.
struct XfeatDetections {
  torch::Tensor keypoints;    // (n, 2) float32 (x, y) in pixels of the image given, pixel centres at integers
  torch::Tensor scores;       // (n) float32, all > 0
  torch::Tensor descriptors;  // (n, 64) float32, unit rows
  int64_t net_height = 0, net_width = 0;  // the network input: the image resized to multiples of 32
  // intermediate
  torch::Tensor net_input;  // (1, C, H', W') the resized image the network saw
  XfeatNetOutput net;
  torch::Tensor heatmap;        // (1, 1, H, W) keypoint probability per network-input pixel
  torch::Tensor nms_keypoints;  // (N, 2) int64 (x, y) local maxima above the threshold, row-major order
  torch::Tensor nms_scores;     // (N) float32
  torch::Tensor topk_idx;       // (min(N, top_k)) int64 into nms_keypoints, descending score
};

class XfeatModel {
 public:
  // `weights` are the 54 tensors of the BatchNorm-folded layout (see xfeat_weights.h, which checks and folds
  // any layout first); they are moved to `device` as contiguous float32.
  XfeatModel(const StateDict& weights, torch::Device device);

  torch::Device device() const { return device_; }

  // `image` (B, C, H, W) float32, C = 1 or 3 (averaged inside the network, as upstream), values in [0, 1],
  // H and W multiples of 8. Thread-safe. On the CPU some layers have faster equivalents of upstream's
  // LibTorch ops; `reference_ops` uses upstream's everywhere (as on a GPU), for tests that compare the two.
  XfeatNetOutput Forward(const torch::Tensor& image, bool reference_ops = false) const;

  // Upstream's XFeat.detectAndCompute on one image (1, C, H, W) float32 in [0, 1] of any size >= 32 x 32:
  // bilinear resize to multiples of 32, network, heatmap, 5x5 NMS, scores, top-k, bicubic descriptors,
  // keypoints scaled back to the given image. Thread-safe.
  XfeatDetections DetectAndCompute(const torch::Tensor& image, const XfeatDetectOptions& options) const;

 private:
  // conv2d (+ ReLU for BasicLayers) in the layout of `x`: dense, or oneDNN's blocked layout.
  torch::Tensor Conv(const torch::Tensor& x, const std::string& name) const;
  torch::Tensor FirstConvOnCpu(const torch::Tensor& x) const;  // block1.0 with OpenCV

  std::map<std::string, XfeatConv> convs_;
  std::map<std::string, std::pair<torch::Tensor, torch::Tensor>> weights_;          // name -> (weight, bias)
  std::map<std::string, std::pair<torch::Tensor, torch::Tensor>> blocked_weights_;  // reordered for oneDNN (CPU)
  torch::Device device_;
};

}  // namespace vmap::neural

namespace vmap::neural {

// Upstream's XFeat.match on (N0, D) and (N1, D) unit descriptors on any device: mutual nearest neighbours by
// cosine similarity, kept when the similarity exceeds `min_cossim` (strictly; min_cossim <= 0 keeps every
// mutual pair, as upstream). Returns (K, 2) int64 [idx0, idx1] in increasing idx0 and their similarities.
std::pair<torch::Tensor, torch::Tensor> XfeatMatch(const torch::Tensor& descriptors0, const torch::Tensor& descriptors1,
                                                   double min_cossim);

}  // namespace vmap::neural
