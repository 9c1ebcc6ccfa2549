#pragma once
// The LibTorch half of vmap (LoFTR, XFeat, ALIKED) is a plugin, libvmap_torch.so beside the vmap binary, loaded the first
// time a command needs it. Linked into the binary, LibTorch's static initialisers cost every command about
// 0.45 s of start-up (vmap info included), LoFTR or not. No LibTorch in this header.

#include <memory>
#include <string>
#include <vector>

#include "vmap/features/matcher.h"
#include "vmap/neural/aliked_options.h"
#include "vmap/neural/loftr_options.h"
#include "vmap/neural/xfeat_options.h"

namespace vmap {

// The entry points of the plugin (see loftr_matcher.h, xfeat_matcher.h and aliked_matcher.h for what they do).
struct TorchPluginApi {
  std::unique_ptr<Matcher> (*create_loftr_matcher)(const LoftrMatcherOptions& options);
  std::vector<std::string> (*loftr_presets_fitting_file)(const std::string& path);
  std::unique_ptr<Matcher> (*create_xfeat_matcher)(const XfeatMatcherOptions& options);
  std::string (*xfeat_weights_layout)(const std::string& path);
  std::unique_ptr<Matcher> (*create_aliked_matcher)(const AlikedMatcherOptions& options);
  std::vector<std::string> (*aliked_models_fitting_file)(const std::string& path);
};

// The plugin's entry points: linked into this program (the neural tests), or loaded from libvmap_torch.so
// beside the executable. Throws InputError naming the library and the fix when it cannot be loaded.
const TorchPluginApi& TorchPlugin();

}  // namespace vmap

// The symbol the plugin exports, and the loader looks up.
extern "C" const vmap::TorchPluginApi* vmap_torch_plugin_api();
