#include "vmap/neural/state_dict.h"

#include <fstream>
#include <iterator>
#include <set>

#include <torch/serialize.h>

#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/neural/checkpoint_reader.h"

namespace vmap::neural {

namespace {

std::string DtypeName(const torch::Tensor& t) {
  switch (t.scalar_type()) {
    case torch::kFloat32:
      return "float32";
    case torch::kFloat16:
      return "float16";
    case torch::kFloat64:
      return "float64";
    case torch::kInt64:
      return "int64";
    default:
      return std::string(c10::toString(t.scalar_type()));
  }
}

std::string DescribeTensor(const std::string& dtype, const std::vector<int64_t>& shape) {
  return dtype + " " + (shape.empty() ? "scalar" : ShapeString(shape));
}

std::string ListKeys(const std::string& title, const std::vector<std::string>& keys) {
  if (keys.empty()) return "";
  constexpr size_t kShown = 12;
  std::string text = "\n  " + title + " (" + std::to_string(keys.size()) + "):";
  for (size_t i = 0; i < keys.size() && i < kShown; ++i) text += "\n    " + keys[i];
  if (keys.size() > kShown) text += "\n    ... and " + std::to_string(keys.size() - kShown) + " more";
  return text;
}

StateDict ReadWithCheckpointReader(const std::string& path, const std::string& model, const std::string& first_error,
                                   size_t file_size) {
  StateDict weights = ReadRefusedWeightsFile(path, model, first_error, file_size);
  if (weights.empty()) throw InputError(model + " weights file '" + path + "' holds no tensors");
  return weights;
}

}  // namespace

StateDict ReadWeightsFile(const std::string& path, const std::string& model) {
  // The largest published weights are some 50 MB: 1 GiB bounds what a wrong or sparse file costs. A FIFO or a
  // device is refused before it is read.
  const std::string text = ReadNamedFile(path, 1ull << 30, model + " weights file", "check the weights path");
  const std::vector<char> bytes(text.begin(), text.end());
  c10::IValue root;
  try {
    root = torch::pickle_load(bytes);
  } catch (const std::exception& e) {
    const std::string reason = e.what();
    return ReadWithCheckpointReader(path, model, reason.substr(0, reason.find('\n')), bytes.size());
  }
  // LibTorch's unpickler turns a collections.OrderedDict into None.
  if (root.isNone()) return ReadWithCheckpointReader(path, model, "OrderedDict", bytes.size());
  if (!root.isGenericDict()) {
    throw InputError(model + " weights file '" + path + "' holds a " + root.tagKind() +
                     ", not a dict of tensors; see `vmap weights` for the supported files");
  }
  auto dict = root.toGenericDict();
  for (const char* nested : {"state_dict", "model_state_dict"}) {
    const auto it = dict.find(c10::IValue(std::string(nested)));
    if (it == dict.end()) continue;
    if (it->value().isNone()) return ReadWithCheckpointReader(path, model, "OrderedDict", bytes.size());
    if (!it->value().isGenericDict()) {
      throw InputError(model + " weights file '" + path + "': '" + nested + "' is not a dict of tensors");
    }
    dict = it->value().toGenericDict();
    break;
  }
  StateDict weights;
  for (const auto& entry : dict) {
    if (!entry.key().isString()) continue;  // not a parameter name
    if (!entry.value().isTensor()) {
      throw InputError(model + " weights file '" + path + "': entry '" + entry.key().toStringRef() +
                       "' is not a tensor; expected a state dict of tensors");
    }
    weights[entry.key().toStringRef()] = entry.value().toTensor();
  }
  if (weights.empty()) throw InputError(model + " weights file '" + path + "' holds no tensors");
  return weights;
}

std::string StateDictMismatch::Describe() const {
  return ListKeys("missing keys", missing) + ListKeys("unexpected keys", unexpected) +
         ListKeys("keys with another shape", wrong_shape);
}

StateDictMismatch CompareStateDict(const StateDict& weights, const std::vector<TensorSpec>& expected) {
  StateDictMismatch result;
  std::set<std::string> expected_keys;
  for (const auto& spec : expected) {
    expected_keys.insert(spec.key);
    const auto it = weights.find(spec.key);
    if (it == weights.end()) {
      result.missing.push_back(spec.key);
      continue;
    }
    const torch::Tensor& tensor = it->second;
    const bool same_kind = (spec.dtype == "float32") == tensor.is_floating_point();
    if (tensor.sizes().vec() != spec.shape || !same_kind) {
      result.wrong_shape.push_back(spec.key + " (file " + DescribeTensor(DtypeName(tensor), tensor.sizes().vec()) +
                                   ", expected " + DescribeTensor(spec.dtype, spec.shape) + ")");
    }
  }
  for (const auto& [key, tensor] : weights) {
    if (!expected_keys.count(key)) result.unexpected.push_back(key);
  }
  return result;
}

}  // namespace vmap::neural
