#include "vmap/features/matcher_plugin.h"

#include <dlfcn.h>
#include <elf.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

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
  // A missing file is dlopen's to say (with the fix below); one that is there must be whole before it is mapped.
  std::error_code exists_error;
  const bool exists = std::filesystem::exists(path, exists_error);
  if (const std::string problem = exists ? IncompleteSharedLibraryProblem(path) : ""; !problem.empty()) {
    throw InputError("the deep matchers need LibTorch, through '" + path + "', which " + problem +
                     "; rebuild vmap (scripts/build.sh) or install it again");
  }
  // Never closed: matchers and features made by the plugin may live until the process ends.
  void* library = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!library) {
    throw InputError("the deep matchers need LibTorch, through '" + path + "', which cannot be loaded (" + dlerror() +
                     "); build vmap with -DVMAP_WITH_TORCH=ON (scripts/build.sh does) and keep libvmap_torch.so "
                     "beside the program that loads it (the vmap binary, the Python module, the ROS nodes)");
  }
  using Entry = const MatcherPluginTable* (*)();
  using Abi = const char* (*)();
  const auto entry = reinterpret_cast<Entry>(dlsym(library, "vmap_matcher_plugin_table"));
  const auto abi = reinterpret_cast<Abi>(dlsym(library, "vmap_matcher_plugin_abi"));
  if (!entry) {
    throw InputError("'" + path + "' is not a vmap LibTorch plugin (no vmap_matcher_plugin_table); rebuild vmap");
  }
  if (!abi) {
    throw InputError("'" + path + "' was built by an older vmap (it names no ABI); rebuild vmap so that " +
                     "libvmap_torch.so and the program that loads it come from one build");
  }
  if (const std::string theirs = abi(), ours = MatcherPluginAbi(); theirs != ours) {
    throw InputError("'" + path + "' was built for another vmap (" + theirs + ") than this one (" + ours +
                     "); rebuild vmap so that libvmap_torch.so and the program that loads it come from one build");
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

std::string IncompleteSharedLibraryProblem(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (!file || error) return "cannot be read";
  const auto read_at = [&file](std::uint64_t offset, void* into, std::size_t bytes) {
    file.seekg(static_cast<std::streamoff>(offset));
    return static_cast<bool>(file.read(static_cast<char*>(into), static_cast<std::streamsize>(bytes)));
  };
  Elf64_Ehdr header{};
  if (!read_at(0, &header, sizeof(header)) || std::memcmp(header.e_ident, ELFMAG, SELFMAG) != 0 ||
      header.e_ident[EI_CLASS] != ELFCLASS64 || header.e_phentsize != sizeof(Elf64_Phdr)) {
    return "is no 64-bit ELF shared library";
  }
  // The program headers, then every segment they have the loader map from the file.
  std::uint64_t end = std::uint64_t{header.e_phoff} + std::uint64_t{header.e_phnum} * sizeof(Elf64_Phdr);
  for (int i = 0; end <= size && i < header.e_phnum; ++i) {
    Elf64_Phdr segment{};
    if (!read_at(header.e_phoff + i * sizeof(Elf64_Phdr), &segment, sizeof(segment))) return "cannot be read";
    if (segment.p_type == PT_LOAD) end = std::max(end, std::uint64_t{segment.p_offset} + segment.p_filesz);
  }
  if (end <= size) return "";
  return fmt::format("is {} bytes, its segments end at byte {}: it is cut short", size, end);
}

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
