#pragma once
// Reading ALIKED weights and checking them against a configuration before use. Includes LibTorch: internal to
// vmap/neural.

#include <string>
#include <vector>

#include "vmap/neural/aliked/aliked_config.h"
#include "vmap/neural/aliked/aliked_model.h"

namespace vmap::neural {

// Reads a `torch.save` zip file holding the state dict: a plain {name: tensor} dict (the shared
// aliked-{t16,n16}.pt), the upstream release files models/aliked-{t16,n16}.pth (a collections.OrderedDict,
// which LibTorch's unpickler cannot build: read with the checkpoint reader), or either under "state_dict".
// Unreadable, truncated or foreign files throw InputError naming `path`.
StateDict ReadAlikedStateDict(const std::string& path);

// Throws InputError listing missing, unexpected and mis-shaped keys (and naming the model the file fits, if
// any) unless `weights` holds exactly the tensors `config` needs.
void CheckAlikedStateDict(const StateDict& weights, const AlikedConfig& config, const std::string& path);

// The models ("t16", "n16") whose key set and shapes `weights` matches exactly.
std::vector<std::string> AlikedModelsFitting(const StateDict& weights);

}  // namespace vmap::neural
