#include "vmap/neural/loftr/loftr_weights.h"

#include <cstdint>

#include "vmap/core/error.h"

namespace vmap::neural {

namespace {

const char kLightningPrefix[] = "matcher.";

StateDictMismatch Compare(const StateDict& weights, const LoftrConfig& config) {
  return CompareStateDict(weights, ExpectedStateDict(config));
}

}  // namespace

StateDict ReadStateDict(const std::string& path) {
  StateDict weights;
  for (auto& [key, tensor] : ReadWeightsFile(path, "LoFTR")) {
    const bool prefixed = key.rfind(kLightningPrefix, 0) == 0;
    weights[prefixed ? key.substr(sizeof(kLightningPrefix) - 1) : key] = tensor;
  }
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
  const StateDictMismatch mismatch = Compare(weights, config);
  if (mismatch.empty()) return;
  std::string message =
      "LoFTR weights file '" + path + "' does not fit the '" + config.preset + "' model:" + mismatch.Describe();
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
