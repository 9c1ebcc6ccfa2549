#pragma once
// The ALIKED network on LibTorch tensors (inference only): dense score map, DKD keypoints and SDDH
// descriptors, as upstream Shiaoming/ALIKED computes them. Internal to vmap/neural: includes LibTorch.

#include <map>
#include <string>

#include <torch/torch.h>

#include "vmap/neural/aliked/aliked_config.h"
#include "vmap/neural/state_dict.h"

namespace vmap::neural {

// Upstream's DKD ("differentiable keypoint detection"), inference part.
struct DkdOptions {
  int radius = 2;                // NMS window 2r+1, border of r pixels without keypoints, soft-argmax window
  int top_k = 1000;              // > 0: the top_k highest NMS peaks, in descending score order
  double score_threshold = 0.2;  // top_k <= 0: NMS peaks above this (0: above the mean score), row-major order
  int max_keypoints = 5000;      // top_k <= 0: at most this many, the highest scores (upstream's n_limit)
  double temperature = 0.1;      // soft-argmax temperature
  bool sub_pixel = true;         // refine by soft-argmax (upstream ALIKED.forward's default)
  // Upstream's top-k returns suppressed pixels (NMS score 0) when an image has fewer than top_k peaks; with
  // this set they are dropped. The golden comparisons turn it off.
  bool drop_suppressed = true;
  // A camera mask at the score map's size, (1, 1, H, W) float: 1 where a peak may be, 0 where none may. The peaks
  // outside it are suppressed before the top_k best are taken, so the mask keeps the whole budget within it (with
  // drop_suppressed). Undefined: everywhere.
  torch::Tensor keep;
};

struct DkdResult {
  torch::Tensor keypoints;   // (N, 2) float (x, y) normalised to [-1, 1] with x_n = x_px / (W - 1) * 2 - 1
  torch::Tensor scores;      // (N) score map sampled bilinearly at the keypoints
  torch::Tensor dispersity;  // (N) score dispersity of the soft-argmax window
};

// Keypoints of a (1, 1, H, W) score map. Works on any device.
DkdResult DetectKeypoints(const torch::Tensor& score_map, const DkdOptions& options);

// Upstream's simple_nms: the score where it is the maximum of its (2r+1)^2 window, after two rounds of
// recovering maxima outside the windows of the maxima found so far; 0 elsewhere.
torch::Tensor SimpleNms(const torch::Tensor& scores, int radius);

// What the network computes densely for one image. The feature map itself is not stored at full
// resolution: the descriptor head reads it only around keypoints (see AlikedModel::FeaturesAt).
struct AlikedDenseMaps {
  torch::Tensor score_map;  // (1, 1, H, W), sigmoid scores, padding removed
  // The four aggregation outputs (selu(conv_k(x_k)), dim/4 channels each) at 1, 1/2, 1/8 and 1/32 of the
  // padded size. The feature map is the L2-normalised concatenation of their bilinear (align_corners)
  // upsamplings to the padded size.
  torch::Tensor level[4];
  int64_t height = 0, width = 0;      // image size (without padding)
  int64_t pad_top = 0, pad_left = 0;  // replicate padding added before the network
  int64_t padded_height = 0, padded_width = 0;
};

struct AlikedDescriptors {
  torch::Tensor descriptors;  // (N, dim) L2-normalised
  torch::Tensor offsets;      // (N, M, 2) SDDH sample offsets (x, y) in pixels of the feature map
};

class AlikedModel {
 public:
  // `weights` must already be checked against the configuration (see aliked_weights.h); they are moved to
  // `device` as float32, with every BatchNorm folded into the convolution before it.
  AlikedModel(AlikedConfig config, const StateDict& weights, torch::Device device);

  const AlikedConfig& config() const { return config_; }
  torch::Device device() const { return device_; }

  // `image` is (1, 3, H, W) float32 in [0, 1], or (1, 1, H, W) for a grey image, which is then treated as its
  // three identical channels (the first convolution's weights are summed over its input channels). Any
  // size of at least 1x1; it is replicate-padded to a multiple of 32 as upstream. Thread-safe.
  AlikedDenseMaps ExtractDenseMaps(const torch::Tensor& image) const;

  // The L2-normalised feature map at integer pixels of the unpadded image: `rows`, `cols` (n) int64, in range.
  // Returns (n, dim). Equal to indexing the full map, which is never built.
  torch::Tensor FeaturesAt(const AlikedDenseMaps& maps, const torch::Tensor& rows, const torch::Tensor& cols) const;

  // The full (1, dim, H, W) feature map, as upstream's extract_dense_map returns it (tests only: large).
  torch::Tensor DenseFeatureMap(const AlikedDenseMaps& maps) const;

  // SDDH descriptors at `keypoints` (N, 2), normalised as DkdResult::keypoints.
  AlikedDescriptors Describe(const AlikedDenseMaps& maps, const torch::Tensor& keypoints) const;

 private:
  const torch::Tensor& W(const std::string& key) const;
  torch::Tensor Conv(const torch::Tensor& x, const std::string& name, int64_t padding) const;
  torch::Tensor BlockConv(const torch::Tensor& x, const std::string& name, bool deformable) const;
  torch::Tensor Block(const torch::Tensor& x, const std::string& name, bool deformable, bool residual) const;

  AlikedConfig config_;
  StateDict weights_;  // BatchNorm folded: "<conv>.weight" and "<conv>.bias" for every conv before a BatchNorm
  torch::Device device_;
};

}  // namespace vmap::neural
