#include "vmap/pipelines/output_policies.h"

#include <filesystem>
#include <set>
#include <string>

#include "vmap/evaluation/evaluation_json.h"
#include "vmap/localization/key_image_store.h"
#include "vmap/map/experiences.h"
#include "vmap/map/map_io.h"
#include "vmap/pipelines/localize_odometry.h"
#include "vmap/report/html_report.h"
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

}  // namespace

OutputPolicy MapOutputPolicy(const std::vector<std::string>& inputs) {
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
  std::set<std::string> names = {
      kMapFileName,          kCorrespondencesFileName,  "keys",          kCameraMaskFileName,
      kExperiencesDirectory, kTeachOdometryFileName,    kReportFileName, kReportAssetsDirectory,
      kEvaluationFileName,   kLocalizationCacheFileName};
  std::vector<OutputInput> inputs;
  for (const std::string& name : names) inputs.push_back({directory / name, "the map's " + name});
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
  CheckOutputFiles(outputs, all);
}

}  // namespace vmap
