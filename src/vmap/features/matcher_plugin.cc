#include "vmap/features/matcher_plugin.h"

#include <dlfcn.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <string>

#include "vmap/core/error.h"

// Defined where the plugin's objects are linked in (the plugin itself, the neural tests); weak, so that
// the binary links without them and loads the plugin instead.
extern "C" const vmap::MatcherPluginTable* vmap_matcher_plugin_table() __attribute__((weak));

namespace vmap {
namespace {

#ifdef VMAP_WITH_TORCH
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
#endif

const MatcherPluginTable* OpenPlugin() {
  if (vmap_matcher_plugin_table) return vmap_matcher_plugin_table();
#ifdef VMAP_WITH_TORCH
  const std::string path = PluginPath().string();
  // Never closed: matchers and features made by the plugin may live until the process ends.
  void* library = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!library) {
    throw InputError("the deep matchers need LibTorch, through '" + path + "', which cannot be loaded (" + dlerror() +
                     "); build vmap with -DVMAP_WITH_TORCH=ON (scripts/build.sh does) and keep libvmap_torch.so "
                     "beside the program that loads it (the vmap binary, the Python module, the ROS nodes)");
  }
  using Entry = const MatcherPluginTable* (*)();
  const auto entry = reinterpret_cast<Entry>(dlsym(library, "vmap_matcher_plugin_table"));
  if (!entry) {
    throw InputError("'" + path + "' is not a vmap LibTorch plugin (no vmap_matcher_plugin_table); rebuild vmap");
  }
  return entry();
#else
  throw InputError(
      "this vmap was built without LibTorch (VMAP_WITH_TORCH=OFF); rebuild with it for the deep "
      "matchers");
#endif
}

std::mutex plugin_mutex;
std::atomic<const MatcherPluginTable*> plugin_table{nullptr};  // set once loaded; failures are not kept

MatcherPluginTable& MutableRegisteredPluginMatchers() {
  static MatcherPluginTable table;
  return table;
}

}  // namespace

const PluginMatcherModel* MatcherPluginTable::Find(const std::string& name) const {
  for (const auto& model : models) {
    if (model.name == name) return &model;
  }
  return nullptr;
}

const MatcherPluginTable& LoadMatcherPlugin() {
  if (const MatcherPluginTable* table = plugin_table.load()) return *table;
  const std::lock_guard<std::mutex> lock(plugin_mutex);
  if (!plugin_table.load()) plugin_table.store(OpenPlugin());  // throws, leaving nothing behind
  return *plugin_table.load();
}

bool MatcherPluginLoaded() { return plugin_table.load() != nullptr; }

std::unique_ptr<Matcher> CreatePluginMatcher(const ModelOptions& options) {
  const PluginMatcherModel* model = LoadMatcherPlugin().Find(options.model());
  if (!model || !model->create) {
    throw InputError(std::string("the LibTorch plugin of this vmap has no matcher '") + options.model() +
                     "'; rebuild vmap so that libvmap_torch.so matches the vmap binary");
  }
  return model->create(options);
}

PluginMatcherRegistration::PluginMatcherRegistration(PluginMatcherModel model) {
  auto& models = MutableRegisteredPluginMatchers().models;
  if (MutableRegisteredPluginMatchers().Find(model.name)) {
    throw std::logic_error("plugin matcher '" + model.name + "' registered twice");
  }
  models.push_back(std::move(model));
  std::sort(models.begin(), models.end(),
            [](const PluginMatcherModel& a, const PluginMatcherModel& b) { return a.name < b.name; });
}

const MatcherPluginTable& RegisteredPluginMatchers() { return MutableRegisteredPluginMatchers(); }

}  // namespace vmap
