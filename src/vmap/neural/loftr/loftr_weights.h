#pragma once
// Reading LoFTR weights from PyTorch files and checking them against an architecture before use.
// Includes LibTorch: internal to vmap/neural.

#include <string>

#include "vmap/neural/loftr/loftr_config.h"
#include "vmap/neural/loftr/loftr_model.h"

namespace vmap::neural {

// Reads a `torch.save` zip file. Accepted layouts: a plain {name: tensor} dict; a dict with the tensors under
// "state_dict" (PyTorch-Lightning checkpoints such as the official outdoor_ds.ckpt, keys prefixed "matcher.")
// or under "model_state_dict" (Coarse_LoFTR_TRT). The "matcher." prefix is removed. Unreadable, truncated or
// foreign files throw InputError naming `path`.
StateDict ReadStateDict(const std::string& path);

// Throws InputError listing missing, unexpected and mis-shaped keys (and which preset the file looks like)
// unless `weights` holds exactly the tensors `config` needs.
void CheckStateDict(const StateDict& weights, const LoftrConfig& config, const std::string& path);

// The presets whose key set and shapes `weights` matches exactly (outdoor and indoor share one).
std::vector<std::string> MatchingPresets(const StateDict& weights);

// Overwrites entries of `weights` with those of `overrides` (e.g. BatchNorm statistics); every override
// must exist in `weights` with the same shape.
void ApplyOverrides(StateDict& weights, const StateDict& overrides, const std::string& path);

}  // namespace vmap::neural
