#pragma once
// The ALIKED architecture as data (Zhao et al., "ALIKED", IEEE TIM 2023; upstream Shiaoming/ALIKED): the channel
// widths of each published configuration and the state dict they imply. No LibTorch in this header.

#include <string>
#include <vector>

#include "vmap/neural/tensor_spec.h"

namespace vmap::neural {

struct AlikedConfig {
  std::string name;                    // "t16" or "n16"
  int c1 = 0, c2 = 0, c3 = 0, c4 = 0;  // widths of blocks 1-4 (full, 1/2, 1/8 and 1/32 resolution)
  int dim = 0;                         // descriptor width; the aggregated feature map has dim channels
  int kernel = 3;                      // SDDH: patch size at the keypoint that predicts the sampling offsets
  int num_samples = 16;                // SDDH: deformable sample positions per keypoint ("M")
};

// "t16" or "n16" (also accepted as "aliked-t16", "aliked-n16"); throws InputError for anything else.
AlikedConfig AlikedPreset(const std::string& name);
const std::vector<std::string>& AlikedPresetNames();

// Every tensor of the upstream module's state_dict(), in registration order: blocks 1-2 plain 3x3 convolutions
// with BatchNorm, blocks 3-4 deformable (offset_conv + regular_conv, no modulation mask), the 1x1 aggregation
// convolutions, the score head and the SDDH descriptor head.
std::vector<TensorSpec> AlikedExpectedStateDict(const AlikedConfig& config);

}  // namespace vmap::neural
