// A LibTorch plugin of another vmap, for the loader's test (features/matcher_registry_test.cc): it exports the
// plugin's symbols, and an ABI that is no build's. Loaded by mistake, its table would be read with the wrong layout.

extern "C" __attribute__((visibility("default"))) const char* vmap_matcher_plugin_abi() {
  return "vmap 0.0.0, another build";
}

extern "C" __attribute__((visibility("default"))) const void* vmap_matcher_plugin_table() { return nullptr; }
