#pragma once
// A network's weights as PyTorch names them. Includes LibTorch: internal to vmap/neural.

#include <map>
#include <string>

#include <torch/torch.h>

#include "vmap/neural/tensor_spec.h"

namespace vmap::neural {

using StateDict = std::map<std::string, torch::Tensor>;

}  // namespace vmap::neural
