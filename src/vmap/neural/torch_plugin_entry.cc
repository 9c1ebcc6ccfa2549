// The entry point of libvmap_torch.so (and of the neural tests, which link the same objects).

#include "vmap/neural/aliked_matcher.h"
#include "vmap/neural/loftr_matcher.h"
#include "vmap/neural/torch_plugin.h"
#include "vmap/neural/xfeat_matcher.h"

extern "C" __attribute__((visibility("default"))) const vmap::TorchPluginApi* vmap_torch_plugin_api() {
  static const vmap::TorchPluginApi api{&vmap::CreateLoftrMatcher, &vmap::LoftrPresetsFittingFile,
                                        &vmap::CreateXfeatMatcher, &vmap::XfeatWeightsLayoutOfFile,
                                        &vmap::CreateAlikedMatcher, &vmap::AlikedModelsFittingFile};
  return &api;
}
