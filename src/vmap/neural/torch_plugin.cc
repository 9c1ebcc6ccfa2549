#include "vmap/neural/torch_plugin.h"

#include <dlfcn.h>

#include <filesystem>
#include <mutex>
#include <string>

#include "vmap/core/error.h"

// Defined where the plugin's objects are linked in (the plugin itself, the neural tests); weak, so that
// the binary links without them and loads the plugin instead.
extern "C" const vmap::TorchPluginApi* vmap_torch_plugin_api() __attribute__((weak));

namespace vmap {
namespace {

// Beside the file that holds this code: the vmap binary, or the shared library vmap is linked into when
// another program (a future Python module, a robot's node) loads it. dladdr names that file; /proc/self/exe
// would name the host program instead.
std::filesystem::path PluginPath() {
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&PluginPath), &info) && info.dli_fname && *info.dli_fname) {
    std::error_code error;
    const std::filesystem::path self = std::filesystem::canonical(info.dli_fname, error);
    if (!error) return self.parent_path() / "libvmap_torch.so";
  }
  return std::filesystem::path(".") / "libvmap_torch.so";
}

const TorchPluginApi* LoadPlugin() {
  if (vmap_torch_plugin_api) return vmap_torch_plugin_api();
  const std::string path = PluginPath().string();
  // Never closed: matchers and features made by the plugin may live until the process ends.
  void* library = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!library) {
    throw InputError("the deep matchers need LibTorch, through '" + path + "', which cannot be loaded (" + dlerror() +
                     "); build vmap with -DVMAP_WITH_TORCH=ON (scripts/build.sh does) and keep libvmap_torch.so "
                     "beside the vmap binary");
  }
  using Entry = const TorchPluginApi* (*)();
  const auto entry = reinterpret_cast<Entry>(dlsym(library, "vmap_torch_plugin_api"));
  if (!entry) throw InputError("'" + path + "' is not a vmap LibTorch plugin (no vmap_torch_plugin_api); rebuild vmap");
  return entry();
}

}  // namespace

const TorchPluginApi& TorchPlugin() {
  // Loaded once per process, on success only: after a failure the next call tries again, so a caller that
  // fixed the cause (installed LibTorch, put the plugin in place) need not restart.
  static std::mutex mutex;
  static const TorchPluginApi* loaded = nullptr;
  const std::lock_guard<std::mutex> lock(mutex);
  if (!loaded) loaded = LoadPlugin();
  return *loaded;
}

}  // namespace vmap
