#pragma once
// A network's weights as PyTorch names them, read from the files users have and compared with what a network
// expects. Shared by every model's weights reader. Includes LibTorch: internal to vmap/neural.

#include <map>
#include <string>
#include <vector>

#include <torch/torch.h>

#include "vmap/neural/tensor_spec.h"

namespace vmap::neural {

using StateDict = std::map<std::string, torch::Tensor>;

// Every tensor of a `torch.save` file: a {name: tensor} dict (model.state_dict()), or a checkpoint dict with
// it under "state_dict" or "model_state_dict". Files LibTorch's unpickler cannot return (a
// collections.OrderedDict, Lightning checkpoints with Python objects) go through the checkpoint reader.
// Unreadable, truncated or foreign files throw InputError naming `model` ("XFeat"), the file and the fix.
StateDict ReadWeightsFile(const std::string& path, const std::string& model);

// How a state dict differs from the tensors a network expects.
struct StateDictMismatch {
  std::vector<std::string> missing, unexpected, wrong_shape;  // keys; wrong_shape says what the file holds
  bool empty() const { return missing.empty() && unexpected.empty() && wrong_shape.empty(); }
  size_t size() const { return missing.size() + unexpected.size() + wrong_shape.size(); }
  // The three lists as lines of an error message: the count and the first keys of each non-empty one.
  std::string Describe() const;
};

// `weights` against `expected`. A float tensor of any precision fits a "float32" entry (weights are converted
// once on load); an integer one fits "int64".
StateDictMismatch CompareStateDict(const StateDict& weights, const std::vector<TensorSpec>& expected);

}  // namespace vmap::neural
