#pragma once
// The LibTorch half of vmap (the deep matchers) is a plugin, libvmap_torch.so beside the vmap binary, loaded
// the first time a deep model is created or inspected. Linked into the binary, LibTorch's static initialisers
// would slow the start-up of every command (vmap info included), deep matcher or not
// (docs/measurements/code-choices.md, "LibTorch as a plugin"). No LibTorch here.
//
// The plugin exports one C symbol, vmap_matcher_plugin_table, returning a table of what it offers per model
// name; each model's LibTorch part adds its row with a PluginMatcherRegistration.

#include <memory>
#include <string>
#include <vector>

#include "vmap/features/matcher.h"
#include "vmap/features/matcher_registry.h"

namespace vmap {

// What the plugin offers for one registered model.
struct PluginMatcherModel {
  std::string name;  // as registered in matcher_registry.h
  std::unique_ptr<Matcher> (*create)(const ModelOptions& options) = nullptr;
  // The weights of this model a file fits, as `vmap weights --model` names them ("coarse", "aliked-t16"),
  // with a note in parentheses where one helps ("xfeat (upstream layout)"); empty when none. Throws
  // InputError when the file cannot be read as weights at all.
  std::vector<std::string> (*weights_fitting_file)(const std::string& path) = nullptr;
};

struct MatcherPluginTable {
  std::vector<PluginMatcherModel> models;                         // by name
  const PluginMatcherModel* Find(const std::string& name) const;  // null when absent
};

// The plugin's table: linked into this program (the neural tests), or loaded from libvmap_torch.so beside the
// file holding this code. Throws InputError naming the library and the fix when it cannot be loaded; a
// failure is not remembered, so a later call (after the file was put in place) may succeed.
const MatcherPluginTable& LoadMatcherPlugin();
// Whether the plugin is loaded or linked in already (loads nothing).
bool MatcherPluginLoaded();

// Creates a plugin model's matcher (LoadMatcherPlugin on first use).
std::unique_ptr<Matcher> CreatePluginMatcher(const ModelOptions& options);

// Inside the plugin: adds a model's row to the table the plugin exports.
struct PluginMatcherRegistration {
  explicit PluginMatcherRegistration(PluginMatcherModel model);
};
// The rows registered in this binary (what the plugin's entry point returns).
const MatcherPluginTable& RegisteredPluginMatchers();

// What the binary and the plugin must agree on to share the table: the compiler and its C++ library ABI, vmap's version
// and the layout of every type that crosses. Each side computes its own; a plugin of another build whose types differ
// would otherwise be read with the wrong layout (a crash at best).
inline std::string MatcherPluginAbi() {
  return std::string("vmap ") + VMAP_VERSION + ", g++ " + __VERSION__ + ", cxx11 abi " +
         std::to_string(_GLIBCXX_USE_CXX11_ABI) + ", layout " + std::to_string(sizeof(MatcherPluginTable)) + "/" +
         std::to_string(sizeof(PluginMatcherModel)) + "/" + std::to_string(sizeof(MatcherOptions)) + "/" +
         std::to_string(sizeof(TentativeMatches)) + "/" + std::to_string(sizeof(std::string));
}

// What a file that should be a shared library lacks of itself: "" when its ELF headers and every segment they announce
// lie within it; otherwise why not ("is 2.1 MB, its segments end at 9.8 MB: it is cut short"). The dynamic loader maps
// the announced segments before it checks anything, and a segment beyond the end of the file is a bus error.
std::string IncompleteSharedLibraryProblem(const std::string& path);

}  // namespace vmap

// The symbols the plugin exports, and the loader looks up: its table, and its MatcherPluginAbi().
extern "C" const vmap::MatcherPluginTable* vmap_matcher_plugin_table();
extern "C" const char* vmap_matcher_plugin_abi();
