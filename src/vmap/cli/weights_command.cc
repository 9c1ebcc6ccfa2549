// vmap weights: where LoFTR, XFeat and ALIKED weights are searched, and getting the official ones into the cache.

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "vmap/cli/commands.h"
#include "vmap/core/error.h"
#include "vmap/neural/sha1.h"
#include "vmap/neural/weights_store.h"
#include "vmap/neural/torch_plugin.h"

namespace vmap::cli {

namespace {

struct WeightsFlags {
  std::string download;     // preset or "all"
  std::string import_file;  // local file to copy into the cache
  std::string verify_file;  // local file to identify
  std::string model;        // preset for --import
  bool no_verify = false;
};

std::string Join(const std::vector<std::string>& items) {
  std::string text;
  for (const auto& item : items) text += (text.empty() ? "" : ", ") + item;
  return text;
}

#ifdef VMAP_WITH_TORCH
// The models a file fits: LoFTR presets, "xfeat (<layout> layout)" and ALIKED models as `--model` names them
// (aliked-t16, aliked-n16). Throws the first reading error when the file cannot be read at all.
std::vector<std::string> ModelsFittingFile(const std::string& path) {
  std::vector<std::string> fits;
  std::string read_error;
  try {
    fits = TorchPlugin().loftr_presets_fitting_file(path);
  } catch (const InputError& error) {
    read_error = error.what();
  }
  try {
    fits.push_back("xfeat (" + TorchPlugin().xfeat_weights_layout(path) + " layout)");
  } catch (const InputError&) {
  }
  try {
    for (const auto& model : TorchPlugin().aliked_models_fitting_file(path)) fits.push_back("aliked-" + model);
  } catch (const InputError&) {
  }
  if (fits.empty() && !read_error.empty()) throw InputError(read_error);
  return fits;
}
#endif

void PrintStatus() {
  std::printf("cache directory  %s\n", neural::WeightsCacheDir().c_str());
  std::printf("                 ($%s if set, else $XDG_CACHE_HOME/vmap/weights, else ~/.cache/vmap/weights)\n",
              neural::kWeightsDirEnv);
  std::printf("--weights FILE overrides the search. Files are checked key by key when loaded.\n\n");
  for (const auto& known : neural::KnownWeightFiles()) {
    std::printf("%-8s %s\n", known.preset.c_str(), known.description.c_str());
    if (known.preset.rfind("aliked-", 0) == 0) {
      std::printf("         layouts: upstream's .pth (OrderedDict state dict) or a plain {name: tensor} dict\n");
    }
    std::string found;
    for (const auto& path : neural::WeightsSearchPaths(known.preset)) {
      std::error_code error;
      const bool exists = std::filesystem::is_regular_file(path, error);
      if (exists && found.empty()) found = path;
      std::printf("         %s %s\n", exists ? (found == path ? "[used]   " : "[present]") : "[absent] ", path.c_str());
    }
    if (found.empty() && !known.url.empty()) {
      std::printf("         get it: vmap weights --download %s   (%s)\n", known.preset.c_str(), known.url.c_str());
    } else if (found.empty()) {
      std::printf("         get it: download the official file, then vmap weights --import FILE --model %s\n",
                  known.preset.c_str());
    }
  }
}

void Verify(const std::string& path) {
  const std::string id = neural::GitBlobId(path);
  std::printf("%s\n  git blob id  %s\n", path.c_str(), id.c_str());
  std::string known_as;
  for (const auto& known : neural::KnownWeightFiles()) {
    if (!known.git_blob_id.empty() && known.git_blob_id == id) known_as = known.file_name;
  }
  std::printf("  known copy   %s\n", known_as.empty() ? "no (not byte-identical to a known published copy)"
                                                      : ("yes: " + known_as).c_str());
#ifdef VMAP_WITH_TORCH
  const auto presets = ModelsFittingFile(path);
  std::printf("  fits         %s\n", presets.empty() ? "no known model" : Join(presets).c_str());
  if (presets.empty()) throw InputError("'" + path + "' is not usable as LoFTR, XFeat or ALIKED weights");
#endif
}

void Run(const WeightsFlags& flags) {
  const std::string cache = neural::WeightsCacheDir();
  bool acted = false;
  if (!flags.download.empty()) {
    std::vector<std::string> presets{flags.download};
    if (flags.download == "all") presets = {"outdoor", "indoor", "xfeat"};
    for (const auto& preset : presets) {
      const auto& known = neural::KnownWeightsFor(preset);
      std::printf("downloading %s from %s ...\n", preset.c_str(), known.url.c_str());
      std::fflush(stdout);
      const std::string path = neural::DownloadWeights(preset, cache, !flags.no_verify);
      std::printf("  saved %s (%s)\n", path.c_str(),
                  flags.no_verify ? "git blob id NOT checked" : ("git blob id " + known.git_blob_id + " verified").c_str());
#ifdef VMAP_WITH_TORCH
      if (flags.no_verify) {
        // The mirror may hold other bytes than the published copy; the layout is then the check left.
        const auto presets = ModelsFittingFile(path);
        std::printf("  fits %s\n", presets.empty() ? "no known model: do not use it" : Join(presets).c_str());
      }
#endif
    }
    acted = true;
  }
  if (!flags.import_file.empty()) {
    if (flags.model.empty()) throw InputError("--import needs --model outdoor|indoor|coarse|xfeat|aliked-t16|aliked-n16");
    const auto& known = neural::KnownWeightsFor(flags.model);
    const std::string expected = flags.no_verify ? "" : known.git_blob_id;
#ifdef VMAP_WITH_TORCH
    // Without a known id the structure is the only check available before the file enters the cache.
    if (flags.model == "xfeat") {
      TorchPlugin().xfeat_weights_layout(flags.import_file);  // throws, listing what does not fit
    } else if (const auto presets = ModelsFittingFile(flags.import_file);
               std::find(presets.begin(), presets.end(), flags.model) == presets.end()) {
      throw InputError("'" + flags.import_file + "' does not fit --model " + flags.model +
                       (presets.empty() ? std::string(" (nor any other model)")
                                        : " (it fits " + Join(presets) + ")"));
    }
#endif
    const std::string path = neural::ImportWeights(flags.import_file, flags.model, expected, cache);
    std::printf("imported %s -> %s (%s)\n", flags.import_file.c_str(), path.c_str(),
                flags.no_verify        ? "git blob id NOT checked (--no-verify)"
                : expected.empty()     ? "no published git blob id for this model; structure checked"
                                       : ("git blob id " + expected + " verified").c_str());
    acted = true;
  }
  if (!flags.verify_file.empty()) {
    Verify(flags.verify_file);
    acted = true;
  }
  if (!acted) PrintStatus();
}

}  // namespace

void AddWeightsCommand(CLI::App& app) {
  auto flags = std::make_shared<WeightsFlags>();
  CLI::App* command = app.add_subcommand(
      "weights", "Show where LoFTR, XFeat and ALIKED weights are searched; download, import or verify weight files");
  command->add_option("--download", flags->download, "Download the official weights: outdoor, indoor, xfeat or all")
      ->check(CLI::IsMember({"outdoor", "indoor", "xfeat", "all"}));
  command->add_option("--import", flags->import_file, "Copy a local weights file into the cache (needs --model)");
  command->add_option("--model", flags->model,
                      "Model of the --import file: outdoor, indoor, coarse, xfeat, aliked-t16 or aliked-n16")
      ->check(CLI::IsMember({"outdoor", "indoor", "coarse", "xfeat", "aliked-t16", "aliked-n16"}));
  command->add_option("--verify", flags->verify_file, "Print a file's git blob id and which model it fits");
  command->add_flag("--no-verify", flags->no_verify, "Skip the git blob id check of --download / --import");
  command->callback([flags] { Run(*flags); });
}

}  // namespace vmap::cli
