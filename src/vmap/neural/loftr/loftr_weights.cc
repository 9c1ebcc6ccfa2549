#include "vmap/neural/loftr/loftr_weights.h"

#include <fstream>
#include <iterator>
#include <set>
#include <sstream>

#include <torch/serialize.h>

#include "vmap/core/error.h"
#include "vmap/neural/checkpoint_reader.h"

namespace vmap::neural {

namespace {

const char kLightningPrefix[] = "matcher.";

std::string DtypeName(const torch::Tensor& t) {
  switch (t.scalar_type()) {
    case torch::kFloat32: return "float32";
    case torch::kFloat16: return "float16";
    case torch::kFloat64: return "float64";
    case torch::kInt64: return "int64";
    default: return std::string(c10::toString(t.scalar_type()));
  }
}

bool SameKind(const std::string& expected, const torch::Tensor& t) {
  // Half or double copies of float weights are fine: they are converted once on load.
  if (expected == "float32") return t.is_floating_point();
  return !t.is_floating_point();
}

struct Mismatch {
  std::vector<std::string> missing, unexpected, wrong_shape;
  bool empty() const { return missing.empty() && unexpected.empty() && wrong_shape.empty(); }
  size_t size() const { return missing.size() + unexpected.size() + wrong_shape.size(); }
};

Mismatch Compare(const StateDict& weights, const LoftrConfig& config) {
  Mismatch result;
  std::set<std::string> expected_keys;
  for (const auto& spec : ExpectedStateDict(config)) {
    expected_keys.insert(spec.key);
    auto it = weights.find(spec.key);
    if (it == weights.end()) {
      result.missing.push_back(spec.key);
    } else if (it->second.sizes().vec() != spec.shape || !SameKind(spec.dtype, it->second)) {
      result.wrong_shape.push_back(spec.key + " (file " + DtypeName(it->second) + " " +
                                   ShapeString(it->second.sizes().vec()) + ", expected " + spec.dtype + " " +
                                   ShapeString(spec.shape) + ")");
    }
  }
  for (const auto& [key, tensor] : weights) {
    if (!expected_keys.count(key)) result.unexpected.push_back(key);
  }
  return result;
}

std::vector<char> ReadBytes(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError("cannot open LoFTR weights file '" + path + "'; check the path given to --weights");
  return std::vector<char>(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
}

// Adds the tensors of `dict` to `out`, dropping the Lightning prefix.
void CollectTensors(const c10::Dict<c10::IValue, c10::IValue>& dict, const std::string& path, StateDict& out) {
  for (const auto& entry : dict) {
    if (!entry.key().isString()) continue;
    std::string key = entry.key().toStringRef();
    if (key.rfind(kLightningPrefix, 0) == 0) key = key.substr(sizeof(kLightningPrefix) - 1);
    if (!entry.value().isTensor()) {
      throw InputError("LoFTR weights file '" + path + "': entry '" + entry.key().toStringRef() +
                       "' is not a tensor; expected a state dict of tensors");
    }
    out[key] = entry.value().toTensor();
  }
}

}  // namespace

// Lightning checkpoints (the official files) hold an OrderedDict and Python objects LibTorch's unpickler
// cannot build; they go through the checkpoint reader, which keeps only what a state dict needs.
static StateDict ReadWithCheckpointReader(const std::string& path, const std::string& first_error, size_t file_size) {
  StateDict weights = ReadRefusedWeightsFile(path, "LoFTR", first_error, file_size);
  StateDict stripped;
  for (auto& [key, tensor] : weights) {
    const bool prefixed = key.rfind(kLightningPrefix, 0) == 0;
    stripped[prefixed ? key.substr(sizeof(kLightningPrefix) - 1) : key] = tensor;
  }
  if (stripped.empty()) throw InputError("LoFTR weights file '" + path + "' holds no tensors");
  return stripped;
}

StateDict ReadStateDict(const std::string& path) {
  const std::vector<char> bytes = ReadBytes(path);
  c10::IValue root;
  try {
    root = torch::pickle_load(bytes);
  } catch (const std::exception& e) {
    std::string reason = e.what();
    return ReadWithCheckpointReader(path, reason.substr(0, reason.find('\n')), bytes.size());
  }
  if (!root.isGenericDict()) {
    throw InputError("LoFTR weights file '" + path + "' holds a " + root.tagKind() +
                     ", not a dict of tensors; see `vmap weights` for the supported files");
  }
  auto dict = root.toGenericDict();
  for (const char* nested : {"state_dict", "model_state_dict"}) {
    auto it = dict.find(c10::IValue(std::string(nested)));
    if (it == dict.end()) continue;
    if (it->value().isNone()) return ReadWithCheckpointReader(path, "OrderedDict", bytes.size());
    if (!it->value().isGenericDict()) {
      throw InputError("LoFTR weights file '" + path + "': '" + nested + "' is not a dict of tensors");
    }
    dict = it->value().toGenericDict();
    break;
  }
  StateDict weights;
  CollectTensors(dict, path, weights);
  if (weights.empty()) throw InputError("LoFTR weights file '" + path + "' holds no tensors");
  return weights;
}

std::vector<std::string> MatchingPresets(const StateDict& weights) {
  std::vector<std::string> presets;
  for (const auto& name : LoftrPresetNames()) {
    if (Compare(weights, LoftrPreset(name)).empty()) presets.push_back(name);
  }
  return presets;
}

void CheckStateDict(const StateDict& weights, const LoftrConfig& config, const std::string& path) {
  const Mismatch mismatch = Compare(weights, config);
  if (mismatch.empty()) return;
  std::string message = "LoFTR weights file '" + path + "' does not fit the '" + config.preset + "' model:" +
                        ListStateDictKeys("missing keys", mismatch.missing) +
                        ListStateDictKeys("unexpected keys", mismatch.unexpected) +
                        ListStateDictKeys("keys with another shape", mismatch.wrong_shape);
  // Point at the preset the file was made for, or the closest one.
  std::string closest;
  size_t closest_size = SIZE_MAX;
  for (const auto& name : LoftrPresetNames()) {
    const size_t n = Compare(weights, LoftrPreset(name)).size();
    if (n < closest_size) closest = name, closest_size = n;
  }
  if (closest_size == 0) {
    message += "\n  The file fits --loftr-model " + closest +
               (closest == "outdoor" || closest == "indoor" ? std::string(" (or the other full model: outdoor and "
                                                                          "indoor share one layout)")
                                                            : std::string()) +
               "; pass that, or weights made for '" + config.preset + "'.";
  } else {
    message += "\n  The file matches no LoFTR preset; the closest is '" + closest + "' (" +
               std::to_string(closest_size) + " differing keys). Is it a LoFTR checkpoint?";
  }
  throw InputError(message);
}

void ApplyOverrides(StateDict& weights, const StateDict& overrides, const std::string& path) {
  for (const auto& [key, tensor] : overrides) {
    auto it = weights.find(key);
    if (it == weights.end() || it->second.sizes() != tensor.sizes()) {
      throw InputError("override file '" + path + "': key '" + key + "' is not in the weights or has another shape");
    }
    it->second = tensor;
  }
}

}  // namespace vmap::neural
