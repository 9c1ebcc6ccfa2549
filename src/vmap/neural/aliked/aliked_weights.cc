#include "vmap/neural/aliked/aliked_weights.h"

#include "vmap/core/error.h"

namespace vmap::neural {

namespace {

StateDictMismatch Compare(const StateDict& weights, const AlikedConfig& config) {
  return CompareStateDict(weights, AlikedExpectedStateDict(config));
}

}  // namespace

StateDict ReadAlikedStateDict(const std::string& path) { return ReadWeightsFile(path, "ALIKED"); }

std::vector<std::string> AlikedModelsFitting(const StateDict& weights) {
  std::vector<std::string> models;
  for (const auto& name : AlikedPresetNames()) {
    if (Compare(weights, AlikedPreset(name)).empty()) models.push_back(name);
  }
  return models;
}

void CheckAlikedStateDict(const StateDict& weights, const AlikedConfig& config, const std::string& path) {
  const StateDictMismatch mismatch = Compare(weights, config);
  if (mismatch.empty()) return;
  std::string message =
      "ALIKED weights file '" + path + "' does not fit the '" + config.name + "' model:" + mismatch.Describe();
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
