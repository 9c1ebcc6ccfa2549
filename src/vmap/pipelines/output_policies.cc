#include "vmap/pipelines/output_policies.h"

#include <algorithm>
#include <filesystem>
#include <set>
#include <string>

#include "vmap/core/temporary_name.h"
#include "vmap/evaluation/evaluation_json.h"
#include "vmap/localization/key_image_store.h"
#include "vmap/map/experiences.h"
#include "vmap/map/map_io.h"
#include "vmap/pipelines/localize_odometry.h"
#include "vmap/report/html_report.h"
#include "vmap/report/map_report_files.h"
#include "vmap/report/summary.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

// The symbolic links in an input folder and in its folders one level down (a sequence's images/, rgb/): frames
// read through them live wherever they point, perhaps in the very map being replaced, which the folder alone does
// not say. The checks compare each by the file it reaches.
void AddLinksInFolder(const fs::path& folder, std::vector<fs::path>* inputs) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) return;
  constexpr int kMostEntries = 1000000;  // a bound on the scan, far beyond any sequence
  int entries = 0;
  for (fs::recursive_directory_iterator it(folder, ec), end; !ec && it != end && ++entries < kMostEntries;
       it.increment(ec)) {
    if (it->is_symlink(ec)) inputs->push_back(it->path());
    if (it.depth() >= 1) it.disable_recursion_pending();
  }
}

// The files of every map an output lies in, whichever command writes it: `vmap simulate --json MAP/map.json` or a
// --csv into MAP/keys/ would otherwise replace a map's own file, where the command's inputs do not name the map.
std::vector<OutputInput> FilesOfMapsAround(const std::vector<OutputFile>& outputs) {
  constexpr int kLevels = 4;  // MAP/experiences/ID/keys/FILE, the deepest a map's files lie
  std::vector<OutputInput> files;
  for (const OutputFile& output : outputs) {
    if (output.path.empty()) continue;
    std::error_code ec;
    fs::path folder = fs::absolute(output.path, ec).parent_path();
    for (int level = 0; level < kLevels && !ec && folder.has_relative_path(); ++level, folder = folder.parent_path()) {
      std::error_code missing;  // set where there is no map.json, which is no reason to stop looking further up
      if (fs::is_regular_file(folder / kMapFileName, missing) && WhyNotAVmapMap(folder).empty()) {
        const std::vector<OutputInput> map = MapInputs(folder.string());
        files.insert(files.end(), map.begin(), map.end());
      }
    }
  }
  return files;
}

// The files a map consists of, and those derived from it (its cache, its report, its evaluation): a rebuilt map
// replaces them all. The teach odometry is not among them: it is the teach run's, put beside the map by a host (the
// ROS node, the simulator) or by hand, and a rebuild of the same run needs it as much.
const std::set<std::string>& MapFileNames() {
  static const std::set<std::string> names = {
      kMapFileName,           kCorrespondencesFileName, "keys",
      kCameraMaskFileName,    kExperiencesDirectory,    kReportFileName,
      kReportAssetsDirectory, kEvaluationFileName,      kLocalizationCacheFileName};
  return names;
}

}  // namespace

OutputPolicy MapOutputPolicy(const std::vector<std::string>& inputs, const std::vector<std::string>& files_beside_map) {
  OutputPolicy policy;
  policy.why_not_ours = WhyNotAVmapMap;
  policy.kind = "a vmap map";
  for (const std::string& input : inputs) {
    if (input.empty()) continue;
    policy.inputs.emplace_back(input);
    AddLinksInFolder(input, &policy.inputs);
  }
  // A map costs a run, and a teach run cannot be made again: one that cannot be put in place is kept beside.
  policy.keep_if_commit_fails = true;
  // A rebuild keeps the teach odometry, notes and runs' outputs the folder held besides the map.
  // An own file's temporary (".experiences.partial-PID-N" of an add that was killed) is its too: carried into the new
  // map, it was kept as if it were the user's.
  policy.is_own_entry = [files_beside_map](const std::string& name) {
    if (MapFileNames().count(name) > 0) return true;
    if (std::find(files_beside_map.begin(), files_beside_map.end(), name) != files_beside_map.end()) return true;
    for (const std::string& own : MapFileNames()) {
      if (TemporaryOwner(name, own) != 0) return true;
    }
    return false;
  };
  return policy;
}

OutputPolicy SweepOutputPolicy(const std::string& input) {
  OutputPolicy policy;
  policy.why_not_ours = WhyNotAVmapSweep;
  policy.kind = "a vmap sweep";
  policy.inputs = {input};
  AddLinksInFolder(input, &policy.inputs);
  policy.keep_if_commit_fails = true;  // its maps, as a map's build keeps its map: the error says where
  return policy;
}

std::vector<OutputInput> MapInputs(const std::string& map_directory) {
  if (map_directory.empty()) return {};
  const fs::path directory(map_directory);
  std::vector<OutputInput> inputs;
  for (const std::string& name : MapFileNames()) {
    if (name != kReportAssetsDirectory) inputs.push_back({directory / name, "the map's " + name});
  }
  // Of the report's folder, only what `vmap report` replaces: a user's files beside them stay (an exported figure,
  // report.md), and a command may write them there.
  const fs::path report = directory / kReportAssetsDirectory;
  std::vector<std::string> replaced = {report::kThumbnailsFolder, report::kMatchFiguresFolder};
  replaced.insert(replaced.end(), std::begin(report::kRouteVideoNames), std::end(report::kRouteVideoNames));
  for (const std::string& name : replaced) {
    inputs.push_back({report / name, std::string("the map's ") + kReportAssetsDirectory + "/" + name});
  }
  inputs.push_back({directory / kTeachOdometryFileName, std::string("the map's ") + kTeachOdometryFileName});
  return inputs;
}

std::vector<OutputInput> NamedInput(const std::string& path, const std::string& what) {
  if (path.empty()) return {};
  return {{fs::path(path), what}};
}

std::vector<OutputInput> ExistingInputs(const std::vector<std::string>& paths, const std::string& what) {
  std::vector<OutputInput> inputs;
  for (const std::string& path : paths) {
    std::error_code ec;
    if (!path.empty() && fs::exists(fs::symlink_status(path, ec))) inputs.push_back({fs::path(path), what});
  }
  return inputs;
}

void CheckOutputs(const std::vector<OutputFile>& outputs, const std::vector<std::vector<OutputInput>>& inputs) {
  std::vector<OutputInput> all;
  for (const auto& group : inputs) all.insert(all.end(), group.begin(), group.end());
  const std::vector<OutputInput> maps = FilesOfMapsAround(outputs);
  all.insert(all.end(), maps.begin(), maps.end());
  CheckOutputFiles(outputs, all);
}

}  // namespace vmap
