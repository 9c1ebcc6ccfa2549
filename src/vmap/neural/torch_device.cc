#include "vmap/neural/torch_device.h"

#include <torch/cuda.h>

#include "vmap/core/error.h"

namespace vmap::neural {

torch::Device ParseTorchDevice(const std::string& name) {
  if (name == "cuda") {
    if (!torch::cuda::is_available()) {
      throw OptionError("device",
                        "cuda: this vmap's LibTorch has no CUDA support or sees no GPU; use cpu (or build "
                        "vmap against a CUDA LibTorch)");
    }
    return torch::Device(torch::kCUDA, 0);
  }
  return torch::Device(torch::kCPU);
}

}  // namespace vmap::neural
