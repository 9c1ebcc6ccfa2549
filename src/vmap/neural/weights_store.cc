#include "vmap/neural/weights_store.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <system_error>

#include "vmap/core/atomic_output.h"
#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/neural/sha1.h"

namespace fs = std::filesystem;

namespace vmap::neural {

namespace {

// The command-line choice a preset stands for, for messages: "--loftr-model coarse", "--matcher xfeat",
// "--aliked-model t16".
std::string ModelFlag(const KnownWeights& known) {
  const std::string& preset = known.preset;
  return known.option + " " + (preset.rfind("aliked-", 0) == 0 ? preset.substr(7) : preset);
}

std::string Env(const char* name) {
  const char* value = std::getenv(name);
  return value ? std::string(value) : std::string();
}

bool IsFile(const std::string& path) {
  std::error_code error;
  return fs::is_regular_file(path, error);
}

// Runs argv without a shell (no quoting issues with paths); returns the exit status, -1 if it could not start.
int RunProgram(const std::vector<std::string>& argv) {
  const pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execvp(args[0], args.data());
    _exit(127);
  }
  int status = 0;
  if (waitpid(pid, &status, 0) < 0) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

bool ProgramInstalled(const std::string& name) {
  for (const char* dir : {"/usr/bin/", "/bin/", "/usr/local/bin/"}) {
    if (access((std::string(dir) + name).c_str(), X_OK) == 0) return true;
  }
  return false;
}

}  // namespace

const std::vector<KnownWeights>& KnownWeightFiles() {
  static const std::vector<KnownWeights> files{
      {"outdoor", "outdoor_ds.ckpt", "https://cmp.felk.cvut.cz/~mishkdmy/models/loftr_outdoor.ckpt",
       "a8c45b0ab725f933c45f001effae25f22a4574dd",
       "official LoFTR outdoor_ds.ckpt (zju3dv/LoFTR, Apache-2.0), 46 MB, mirrored by Kornia", "", "--loftr-model"},
      {"indoor", "indoor_ds_new.ckpt", "https://cmp.felk.cvut.cz/~mishkdmy/models/loftr_indoor_ds_new.ckpt",
       "e7cb02c2c629d50e24ec9ecacf4981904979907b",
       "official LoFTR indoor_ds_new.ckpt (zju3dv/LoFTR, Apache-2.0), 46 MB, mirrored by Kornia", "", "--loftr-model"},
      {"coarse", "loftr_coarse_teacher.pt", "", "",
       "Coarse-LoFTR student (Kolkir/Coarse_LoFTR_TRT, Apache-2.0) as a plain state dict; ships in "
       "shared/weights/loftr_coarse",
       "weights/loftr_coarse/loftr_coarse_teacher.pt", "--loftr-model"},
      {"xfeat", "xfeat.pt", "https://github.com/verlab/accelerated_features/raw/main/weights/xfeat.pt",
       "9da942e9c7406b8add3746bf98d4b1840233cd92",
       "XFeat (verlab/accelerated_features, Apache-2.0): the official weights/xfeat.pt, 6 MB, or the BatchNorm-folded "
       "xfeat_folded.pt of shared/weights/xfeat; both layouts load",
       "weights/xfeat/xfeat_folded.pt", "--matcher"},
      // Upstream releases these as models/aliked-*.pth (a collections.OrderedDict state dict); the shared folder
      // holds the same tensors as plain dicts (*.pt). Both layouts load.
      {"aliked-t16", "aliked-t16.pth", "", "",
       "ALIKED-T16 (Shiaoming/ALIKED, BSD-3-Clause), 0.8 MB; official file "
       "https://github.com/Shiaoming/ALIKED/raw/main/models/aliked-t16.pth",
       "weights/aliked/aliked-t16.pt", "--aliked-model"},
      {"aliked-n16", "aliked-n16.pth", "", "",
       "ALIKED-N16 (Shiaoming/ALIKED, BSD-3-Clause), 2.7 MB; official file "
       "https://github.com/Shiaoming/ALIKED/raw/main/models/aliked-n16.pth",
       "weights/aliked/aliked-n16.pt", "--aliked-model"},
  };
  return files;
}

const KnownWeights& KnownWeightsFor(const std::string& preset) {
  for (const auto& known : KnownWeightFiles()) {
    if (known.preset == preset) return known;
  }
  throw InputError("unknown model '" + preset +
                   "'; use outdoor, indoor, coarse (LoFTR), xfeat, aliked-t16 or aliked-n16");
}

std::string WeightsCacheDir() {
  if (auto dir = Env(kWeightsDirEnv); !dir.empty()) return dir;
  if (auto xdg = Env("XDG_CACHE_HOME"); !xdg.empty()) return xdg + "/vmap/weights";
  if (auto home = Env("HOME"); !home.empty()) return home + "/.cache/vmap/weights";
  return ".vmap-weights";
}

std::vector<std::string> WeightsSearchPaths(const std::string& preset) {
  const auto& known = KnownWeightsFor(preset);
  std::vector<std::string> paths{WeightsCacheDir() + "/" + known.file_name};
  if (!known.shared_file.empty()) {
    paths.push_back("../shared/" + known.shared_file);
#ifdef VMAP_DEFAULT_SHARED_DIR
    paths.push_back(std::string(VMAP_DEFAULT_SHARED_DIR) + "/" + known.shared_file);
#endif
  }
  return paths;
}

std::string LocateWeights(const std::string& preset, const std::string& explicit_path) {
  // Absolute: a map records the file its matcher used, and a relative name would be read from wherever a later
  // command runs (another file of that name, or none and another search).
  const auto absolute = [](const std::string& path) {
    std::error_code ec;
    const std::filesystem::path full = std::filesystem::absolute(path, ec);
    return ec ? path : full.lexically_normal().string();
  };
  if (!explicit_path.empty()) {
    std::string why_not;
    if (ContainedFile::OpenRegular(explicit_path, &why_not)) return absolute(explicit_path);
    throw OptionError("weights", "file '" + explicit_path + "' " + why_not + "; give the weights file");
  }
  const auto paths = WeightsSearchPaths(preset);
  for (const auto& path : paths) {
    if (IsFile(path)) return absolute(path);
  }
  const auto& known = KnownWeightsFor(preset);
  std::string message = "no weights for " + ModelFlag(known) + "; searched:";
  for (const auto& path : paths) message += "\n  " + path;
  if (!known.url.empty()) {
    message += "\nGet them with `vmap weights --download " + preset + "` (" + known.url +
               "), or pass a file with --weights. The cache directory can be moved with $" + kWeightsDirEnv + ".";
  } else {
    message += "\nPass the file with --weights, or copy it into the cache with `vmap weights --import FILE --model " +
               preset + "` (" + known.description + ").";
  }
  throw InputError(message);
}

std::string ImportWeights(const std::string& source, const std::string& preset, const std::string& expected_blob_id,
                          const std::string& cache_dir) {
  const auto& known = KnownWeightsFor(preset);
  if (!IsFile(source)) throw InputError("cannot import '" + source + "': no such file");
  if (!expected_blob_id.empty()) {
    const std::string actual = GitBlobId(source);
    if (actual != expected_blob_id) {
      throw InputError("'" + source + "' is not the expected " + preset + " weights: its git blob id is " + actual +
                       ", expected " + expected_blob_id +
                       ". The file is corrupt, truncated or another version; a copy you trust imports with "
                       "--no-verify, its structure checked.");
    }
  }
  std::error_code error;
  fs::create_directories(cache_dir, error);
  if (error) throw InputError("cannot create the weights cache directory '" + cache_dir + "': " + error.message());
  const std::string target = cache_dir + "/" + known.file_name;
  // Read as every weights file is (a regular file, at most 1 GiB), then written as every output is: never over
  // a symbolic link, a device or a read-only file.
  WriteFileAtomically(target, ReadNamedFile(source, 1ull << 30, "weights file", "give the weights file to import"));
  return target;
}

std::string DownloadWeights(const std::string& preset, const std::string& cache_dir, bool verify) {
  const auto& known = KnownWeightsFor(preset);
  if (known.url.empty()) {
    throw InputError("there is no download for " + ModelFlag(known) + ": " + known.description);
  }
  std::error_code error;
  fs::create_directories(cache_dir, error);
  if (error) throw InputError("cannot create the weights cache directory '" + cache_dir + "': " + error.message());
  const std::string download = cache_dir + "/" + known.file_name + ".download";
  int status;
  if (ProgramInstalled("curl")) {
    status = RunProgram({"curl", "--fail", "--location", "--silent", "--show-error", "--output", download, known.url});
  } else if (ProgramInstalled("wget")) {
    status = RunProgram({"wget", "--quiet", "--output-document", download, known.url});
  } else {
    throw InputError("neither curl nor wget is installed; download " + known.url +
                     " yourself and run `vmap weights "
                     "--import FILE --model " +
                     preset + "`");
  }
  if (status != 0) {
    fs::remove(download, error);
    throw InputError("downloading " + known.url + " failed (exit status " + std::to_string(status) +
                     "); check the network, or fetch the file yourself and use `vmap weights --import`");
  }
  try {
    const std::string cached = ImportWeights(download, preset, verify ? known.git_blob_id : "", cache_dir);
    fs::remove(download, error);
    return cached;
  } catch (...) {
    fs::remove(download, error);
    throw;
  }
}

}  // namespace vmap::neural
