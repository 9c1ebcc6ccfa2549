#pragma once
// What a network expects of its weights, shared by the models' weight readers. No LibTorch in this header.

#include <cstdint>
#include <string>
#include <vector>

namespace vmap::neural {

// One entry of a state dict as PyTorch names it ("backbone.layer1.0.conv1.weight").
struct TensorSpec {
  std::string key;
  std::string dtype;  // "float32" or "int64"
  std::vector<int64_t> shape;
};

std::string ShapeString(const std::vector<int64_t>& shape);  // "128x1x7x7"; "" for a scalar

}  // namespace vmap::neural
