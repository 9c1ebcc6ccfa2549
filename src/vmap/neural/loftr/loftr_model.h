#pragma once
// The LoFTR network on LibTorch tensors (inference only). Internal to vmap/neural: this header includes
// LibTorch, so only the few .cc files that run the network include it.

#include <string>

#include <torch/torch.h>

#include "vmap/neural/loftr/loftr_config.h"
#include "vmap/neural/state_dict.h"

namespace vmap::neural {

// What one image contributes to every pair it is part of; computed once by LoftrModel::Extract.
struct LoftrImageFeatures {
  torch::Tensor coarse_backbone;  // (1, C, hc, wc) backbone output (kept for tests)
  torch::Tensor coarse;           // (1, hc*wc, C) backbone + positional encoding, row-major tokens
  torch::Tensor fine;             // (1, Cf, hf, wf); undefined without a fine level
  int64_t height = 0, width = 0;  // network input size
  int64_t coarse_h = 0, coarse_w = 0;
};

// Everything a pair produces, intermediate tensors included so tests can compare each stage.
struct LoftrPairOutput {
  torch::Tensor feat_c0, feat_c1;  // (1, L, C) after the coarse transformer
  torch::Tensor conf;              // (1, L0, L1) dual-softmax confidence (only when keep_conf is set)
  torch::Tensor row_max, row_argmax, col_max, col_argmax;  // (L0) and (L1) over the whole matrix
  torch::Tensor i_ids, j_ids;                              // (M) int64 flat coarse indices, i ascending
  torch::Tensor mconf;                                     // (M)
  torch::Tensor mkpts0_c, mkpts1_c;    // (M, 2) network-input pixels, top-left corner of the coarse cell
  torch::Tensor fine_pre0, fine_pre1;  // (M, ww, Cf) fine windows before the fine transformer
  torch::Tensor fine0, fine1;          // (M, ww, Cf) after it
  torch::Tensor expec_f;               // (M, 3) x, y in [-1, 1] over the window and the spread
  torch::Tensor mkpts0_f, mkpts1_f;    // (M, 2)
};

class LoftrModel {
 public:
  // `weights` must already be checked against the configuration (see loftr_weights.h); they are moved to
  // `device` and stored as float32. BatchNorm layers are used with their running statistics.
  LoftrModel(LoftrConfig config, const StateDict& weights, torch::Device device);

  const LoftrConfig& config() const { return config_; }
  torch::Device device() const { return device_; }
  double threshold() const { return threshold_; }
  void set_threshold(double threshold) { threshold_ = threshold; }

  // `image` is (1, 1, H, W) float32 in [0, 1], H and W multiples of the coarse stride. Thread-safe.
  LoftrImageFeatures Extract(const torch::Tensor& image) const;
  // Thread-safe. `keep_conf` keeps the full confidence matrix in the output (large: L0 x L1 floats).
  LoftrPairOutput Match(const LoftrImageFeatures& image0, const LoftrImageFeatures& image1,
                        bool keep_conf = false) const;

  // The positional encoding added to coarse features of an hc x wc grid: (1, C, hc, wc).
  torch::Tensor PositionalEncoding(int64_t coarse_h, int64_t coarse_w) const;

 private:
  const torch::Tensor& W(const std::string& key) const;
  torch::Tensor ConvBn(const torch::Tensor& x, const std::string& conv, const std::string& bn, int64_t stride,
                       int64_t padding) const;
  torch::Tensor BatchNorm(const torch::Tensor& x, const std::string& bn) const;
  torch::Tensor ResidualBlock(const torch::Tensor& x, const std::string& prefix, bool has_projection,
                              int64_t stride) const;
  torch::Tensor EncoderLayer(const torch::Tensor& x, const torch::Tensor& source, const std::string& prefix,
                             int64_t nhead, double norm_eps) const;
  void Transformer(torch::Tensor& feat0, torch::Tensor& feat1, const std::string& prefix, int num_pairs, int64_t nhead,
                   double norm_eps) const;
  void FineStage(const LoftrImageFeatures& image0, const LoftrImageFeatures& image1, LoftrPairOutput& out) const;

  LoftrConfig config_;
  StateDict weights_;
  torch::Device device_;
  double threshold_;
};

}  // namespace vmap::neural
