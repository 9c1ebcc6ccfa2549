#include "vmap/neural/aliked/aliked_weights.h"

#include <fstream>
#include <iterator>
#include <set>

#include <torch/serialize.h>

#include "vmap/core/error.h"
#include "vmap/neural/checkpoint_reader.h"

namespace vmap::neural {

namespace {

std::string DtypeName(const torch::Tensor& t) {
  switch (t.scalar_type()) {
    case torch::kFloat32: return "float32";
    case torch::kFloat16: return "float16";
    case torch::kFloat64: return "float64";
    case torch::kInt64: return "int64";
    default: return std::string(c10::toString(t.scalar_type()));
  }
}

struct Mismatch {
  std::vector<std::string> missing, unexpected, wrong_shape;
  bool empty() const { return missing.empty() && unexpected.empty() && wrong_shape.empty(); }
  size_t size() const { return missing.size() + unexpected.size() + wrong_shape.size(); }
};

Mismatch Compare(const StateDict& weights, const AlikedConfig& config) {
  Mismatch result;
  std::set<std::string> expected_keys;
  for (const auto& spec : AlikedExpectedStateDict(config)) {
    expected_keys.insert(spec.key);
    auto it = weights.find(spec.key);
    if (it == weights.end()) {
      result.missing.push_back(spec.key);
      continue;
    }
    // Half or double copies of float weights are fine: they are converted once on load.
    const bool same_kind = (spec.dtype == "float32") == it->second.is_floating_point();
    if (it->second.sizes().vec() != spec.shape || !same_kind) {
      result.wrong_shape.push_back(spec.key + " (file " + DtypeName(it->second) + " " +
                                   ShapeString(it->second.sizes().vec()) + ", expected " + spec.dtype + " " +
                                   ShapeString(spec.shape) + ")");
    }
  }
  for (const auto& entry : weights) {
    if (!expected_keys.count(entry.first)) result.unexpected.push_back(entry.first);
  }
  return result;
}

// The collections.OrderedDict of upstream's .pth files (and anything else LibTorch's unpickler rejects).
StateDict ReadWithCheckpointReader(const std::string& path, const std::string& first_error, size_t file_size) {
  StateDict weights = ReadRefusedWeightsFile(path, "ALIKED", first_error, file_size);
  if (weights.empty()) throw InputError("ALIKED weights file '" + path + "' holds no tensors");
  return weights;
}

}  // namespace

StateDict ReadAlikedStateDict(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError("cannot open ALIKED weights file '" + path + "'; check the path given to --weights");
  const std::vector<char> bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  c10::IValue root;
  try {
    root = torch::pickle_load(bytes);
  } catch (const std::exception& e) {
    const std::string reason = e.what();
    return ReadWithCheckpointReader(path, reason.substr(0, reason.find('\n')), bytes.size());
  }
  // LibTorch turns an OrderedDict into None.
  if (root.isNone()) return ReadWithCheckpointReader(path, "OrderedDict", bytes.size());
  if (!root.isGenericDict()) {
    throw InputError("ALIKED weights file '" + path + "' holds a " + root.tagKind() +
                     ", not a dict of tensors; see `vmap weights` for the supported files");
  }
  auto dict = root.toGenericDict();
  auto nested = dict.find(c10::IValue(std::string("state_dict")));
  if (nested != dict.end()) {
    if (nested->value().isNone()) return ReadWithCheckpointReader(path, "OrderedDict", bytes.size());
    if (!nested->value().isGenericDict()) {
      throw InputError("ALIKED weights file '" + path + "': 'state_dict' is not a dict of tensors");
    }
    dict = nested->value().toGenericDict();
  }
  StateDict weights;
  for (const auto& entry : dict) {
    if (!entry.key().isString()) continue;
    if (!entry.value().isTensor()) {
      throw InputError("ALIKED weights file '" + path + "': entry '" + entry.key().toStringRef() +
                       "' is not a tensor; expected a state dict of tensors");
    }
    weights[entry.key().toStringRef()] = entry.value().toTensor();
  }
  if (weights.empty()) throw InputError("ALIKED weights file '" + path + "' holds no tensors");
  return weights;
}

std::vector<std::string> AlikedModelsFitting(const StateDict& weights) {
  std::vector<std::string> models;
  for (const auto& name : AlikedPresetNames()) {
    if (Compare(weights, AlikedPreset(name)).empty()) models.push_back(name);
  }
  return models;
}

void CheckAlikedStateDict(const StateDict& weights, const AlikedConfig& config, const std::string& path) {
  const Mismatch mismatch = Compare(weights, config);
  if (mismatch.empty()) return;
  std::string message = "ALIKED weights file '" + path + "' does not fit the '" + config.name + "' model:" +
                        ListStateDictKeys("missing keys", mismatch.missing) +
                        ListStateDictKeys("unexpected keys", mismatch.unexpected) +
                        ListStateDictKeys("keys with another shape", mismatch.wrong_shape);
  const auto fitting = AlikedModelsFitting(weights);
  if (!fitting.empty()) {
    message += "\n  The file fits --aliked-model " + fitting.front() + "; pass that, or weights made for '" +
               config.name + "'.";
  } else {
    message += "\n  The file fits no ALIKED model (t16, n16). Is it an ALIKED state dict?";
  }
  throw InputError(message);
}

}  // namespace vmap::neural
