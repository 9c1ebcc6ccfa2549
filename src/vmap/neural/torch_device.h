#pragma once
// The LibTorch device of a deep matcher's `--device` option, shared by every model of the plugin.

#include <string>

#include <torch/types.h>

namespace vmap::neural {

// "cuda" (the first GPU) or anything else: the CPU (the options' Check() has refused unknown names). Throws
// InputError when CUDA is asked for and this LibTorch has no CUDA or sees no GPU.
torch::Device ParseTorchDevice(const std::string& name);

}  // namespace vmap::neural
