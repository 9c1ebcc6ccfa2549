// vmap weights: where LoFTR, XFeat and ALIKED weights are searched, and getting the official ones into the cache.

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "vmap/cli/commands.h"
#include "vmap/core/error.h"
#include "vmap/features/matcher_plugin.h"
#include "vmap/features/matcher_registry.h"
#include "vmap/neural/sha1.h"
#include "vmap/neural/weights_store.h"

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
// What a file fits, asked of each model of the plugin (features/matcher_plugin.h): the weights as `--model`
// names them ("coarse", "aliked-t16"), notes in parentheses ("xfeat (folded layout)").
struct FileFits {
  std::vector<std::string> fits;
  std::vector<std::string> refused_models;             // the models that could not read the file,
  std::vector<std::string> refusals;                   // and why
  std::vector<std::string> refusals_by_model() const;  // "xfeat: ..."
};

std::vector<std::string> FileFits::refusals_by_model() const {
  std::vector<std::string> named;
  for (size_t i = 0; i < refusals.size(); ++i) named.push_back(refused_models[i] + ": " + refusals[i]);
  return named;
}

FileFits ModelsFittingFile(const std::string& path) {
  FileFits result;
  for (const PluginMatcherModel& model : LoadMatcherPlugin().models) {
    if (!model.weights_fitting_file) continue;
    try {
      for (auto& fit : model.weights_fitting_file(path)) result.fits.push_back(std::move(fit));
    } catch (const InputError& error) {
      result.refused_models.push_back(model.name);
      result.refusals.push_back(error.what());
    }
  }
  return result;
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
  std::printf("  known copy   %s\n",
              known_as.empty() ? "no (not byte-identical to a known published copy)" : ("yes: " + known_as).c_str());
#ifdef VMAP_WITH_TORCH
  const FileFits fits = ModelsFittingFile(path);
  std::printf("  fits         %s\n", fits.fits.empty() ? "no known model" : Join(fits.fits).c_str());
  if (fits.fits.empty()) {
    // Each model's reason: the file is the weights of none, whichever the user meant it for.
    throw InputError("'" + path + "' is not usable as weights of any deep matcher (" + Join(fits.refusals_by_model()) +
                     ")");
  }
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
      std::printf(
          "  saved %s (%s)\n", path.c_str(),
          flags.no_verify ? "git blob id NOT checked" : ("git blob id " + known.git_blob_id + " verified").c_str());
#ifdef VMAP_WITH_TORCH
      if (flags.no_verify) {
        // The mirror may hold other bytes than the published copy; the layout is then the check left.
        const auto fits = ModelsFittingFile(path).fits;
        std::printf("  fits %s\n", fits.empty() ? "no known model: do not use it" : Join(fits).c_str());
      }
#endif
    }
    acted = true;
  }
  if (!flags.import_file.empty()) {
    if (flags.model.empty())
      throw InputError("--import needs --model outdoor|indoor|coarse|xfeat|aliked-t16|aliked-n16");
    const auto& known = neural::KnownWeightsFor(flags.model);
    const std::string expected = flags.no_verify ? "" : known.git_blob_id;
#ifdef VMAP_WITH_TORCH
    // Without a known id the structure is the only check available before the file enters the cache.
    const FileFits fits = ModelsFittingFile(flags.import_file);
    const auto is_model = [&](const std::string& fit) { return fit.substr(0, fit.find(" (")) == flags.model; };
    if (std::none_of(fits.fits.begin(), fits.fits.end(), is_model)) {
      // Another model's file: which one is the answer; the other models' refusals would bury it.
      if (!fits.fits.empty()) {
        throw InputError("'" + flags.import_file + "' does not fit --model " + flags.model + " (it fits " +
                         Join(fits.fits) + "); give --model as the file fits");
      }
      throw InputError("'" + flags.import_file + "' does not fit --model " + flags.model + " (nor any other model" +
                       (fits.refusals.empty() ? "" : "; " + Join(fits.refusals_by_model())) + ")");
    }
    // The published id is the official file's: a file of another layout (XFeat's BatchNorm-folded one, which
    // shared/weights holds) never has it, and is no corrupt copy; --no-verify takes it on its structure.
    const auto in_other_layout = std::find_if(fits.fits.begin(), fits.fits.end(), [&](const std::string& fit) {
      return is_model(fit) && fit.find(" layout)") != std::string::npos &&
             fit.find("(official layout)") == std::string::npos;
    });
    if (in_other_layout != fits.fits.end() && !expected.empty()) {
      throw InputError("'" + flags.import_file + "' is " + *in_other_layout + ", not the published " + known.file_name +
                       " whose git blob id vmap checks; import it with --no-verify (its structure " + "is checked)");
    }
#endif
    const std::string path = neural::ImportWeights(flags.import_file, flags.model, expected, cache);
    std::printf("imported %s -> %s (%s)\n", flags.import_file.c_str(), path.c_str(),
                flags.no_verify    ? "git blob id NOT checked (--no-verify)"
                : expected.empty() ? "no published git blob id for this model; structure checked"
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
  command
      ->add_option("--model", flags->model,
                   "Model of the --import file: outdoor, indoor, coarse, xfeat, aliked-t16 or aliked-n16")
      ->check(CLI::IsMember({"outdoor", "indoor", "coarse", "xfeat", "aliked-t16", "aliked-n16"}));
  command->add_option("--verify", flags->verify_file, "Print a file's git blob id and which model it fits");
  command->add_flag("--no-verify", flags->no_verify, "Skip the git blob id check of --download / --import");
  command->callback([flags] { Run(*flags); });
}

}  // namespace vmap::cli
