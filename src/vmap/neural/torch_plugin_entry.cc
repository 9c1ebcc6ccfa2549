// The entry point of libvmap_torch.so (and of the neural tests, which link the same objects): the table each
// model's LibTorch part registered into (PluginMatcherRegistration in neural/<model>/<model>_matcher.cc).

#include <string>

#include "vmap/features/matcher_plugin.h"

extern "C" __attribute__((visibility("default"))) const vmap::MatcherPluginTable* vmap_matcher_plugin_table() {
  return &vmap::RegisteredPluginMatchers();
}

extern "C" __attribute__((visibility("default"))) const char* vmap_matcher_plugin_abi() {
  static const std::string abi = vmap::MatcherPluginAbi();
  return abi.c_str();
}
