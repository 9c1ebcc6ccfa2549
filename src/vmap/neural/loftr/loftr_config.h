#pragma once
// The LoFTR architecture as data: one configuration drives the network, the expected state dict and the
// coarse matching rules, so the presets differ only in these values. This header does not include LibTorch.

#include <cstdint>
#include <string>
#include <vector>

#include "vmap/neural/tensor_spec.h"

namespace vmap::neural {

enum class BackboneKind {
  kResNetFpn8_2,   // coarse features at 1/8, fine at 1/2 (official LoFTR)
  kResNetFpn16_4,  // coarse features at 1/16, "fine" at 1/4 (Coarse-LoFTR student; the 1/4 map is unused)
};

struct LoftrConfig {
  std::string preset;
  BackboneKind backbone = BackboneKind::kResNetFpn8_2;
  int initial_dim = 128;
  std::vector<int> block_dims{128, 196, 256};
  int coarse_stride = 8;  // input pixels per coarse cell

  // Coarse transformer.
  int d_model = 256;
  int nhead = 8;
  int num_coarse_layer_pairs = 4;  // each pair is [self, cross]
  double layer_norm_eps = 1e-5;
  double attention_eps = 1e-6;
  // The released outdoor model was trained with a positional encoding whose frequency term has an operator
  // precedence slip upstream; the weights only work with that encoding, so it is reproduced, not fixed.
  bool temp_bug_fix = false;

  // Dual-softmax coarse matching.
  double temperature = 0.1;
  double threshold = 0.2;  // conf > threshold
  int border_removal = 2;  // coarse cells excluded at each image border

  // Fine level (absent for the coarse student).
  bool has_fine = true;
  int fine_stride = 2;  // input pixels per fine cell
  int fine_window = 5;
  int fine_d_model = 128;
  int fine_nhead = 8;
  int num_fine_layer_pairs = 1;
  bool fine_concat_coarse_feat = true;
};

// "outdoor", "indoor" or "coarse"; throws InputError for anything else.
LoftrConfig LoftrPreset(const std::string& name);
const std::vector<std::string>& LoftrPresetNames();

// Every tensor the configured network needs, in the order PyTorch's module registration lists them.
std::vector<TensorSpec> ExpectedStateDict(const LoftrConfig& config);

}  // namespace vmap::neural
