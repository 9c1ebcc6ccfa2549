#include "vmap/neural/tensor_spec.h"

namespace vmap::neural {

std::string ShapeString(const std::vector<int64_t>& shape) {
  std::string text;
  for (size_t i = 0; i < shape.size(); ++i) {
    if (i) text += "x";
    text += std::to_string(shape[i]);
  }
  return text;
}

}  // namespace vmap::neural
