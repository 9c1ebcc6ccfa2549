#include "vmap/localization/add_experience.h"

#include <cmath>
#include <memory>
#include <system_error>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "vmap/core/atomic_output.h"
#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/localization/localization_map.h"
#include "vmap/map/map_io.h"

namespace vmap {
namespace fs = std::filesystem;
using nlohmann::json;

void AddExperienceOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.VisitNested("localizer", localizer, Nesting{false, {"verifier", "translation"}});
  visitor.VisitNested("run", run);
}

void AddExperienceOptions::Check() const {
  CheckField("localizer", localizer);
  CheckField("run", run);
}

ExperienceViewPicker::ExperienceViewPicker(int num_keys) : best_(static_cast<size_t>(num_keys)) {}

std::vector<int> ExperienceViewPicker::Offer(const LocalizationResult& result) {
  std::vector<int> improved;
  for (const KeyComparison* c : {&result.to_key, &result.to_next}) {
    if (c->key < 0 || c->key >= static_cast<int>(best_.size()) || !c->accepted || !std::isfinite(c->heading.px)) {
      continue;
    }
    ExperienceView& view = best_[c->key];
    if (c->num_verified <= view.num_verified) continue;
    view.key = c->key;
    view.frame_index = result.frame_index;
    view.source_index = result.source_index;
    view.timestamp = result.timestamp;
    view.source_name = result.source_name;
    view.heading_px = c->heading.px;
    view.num_verified = c->num_verified;
    improved.push_back(c->key);
  }
  return improved;
}

std::vector<ExperienceView> ExperienceViewPicker::Views() const {
  std::vector<ExperienceView> views;
  for (const ExperienceView& v : best_) {
    if (v.num_verified > 0) views.push_back(v);
  }
  return views;
}

namespace {

std::string SizeText(const cv::Size& size) { return fmt::format("{}x{}", size.width, size.height); }

// Removes what an interrupted add created, so that the map is left as it was.
class Undo {
 public:
  void Add(fs::path path) { paths_.push_back(std::move(path)); }
  void Dismiss() { paths_.clear(); }
  ~Undo() {
    for (auto it = paths_.rbegin(); it != paths_.rend(); ++it) {
      std::error_code ignored;
      fs::remove_all(*it, ignored);
    }
  }

 private:
  std::vector<fs::path> paths_;
};

}  // namespace

AddExperienceSummary AddExperience(const fs::path& map_directory, FrameSource& source, const std::string& source_path,
                                   const AddExperienceOptions& options) {
  options.Check();
  KeyImageStoreOptions store_options;
  store_options.use_cache = false;
  store_options.thumbnail_width = options.localizer.ranking.thumbnail_width;
  const LocalizationMap opened = OpenLocalizationMap(map_directory, store_options);
  const VisualMap& map = opened.map;
  const fs::path map_file = map_directory / kMapFileName;
  // map.json as it is now: everything but `experiences` is written back as it was.
  const ContainedJson parsed = ReadContainedJson(map_directory, kMapFileName, kMaxMapJsonBytes, 1ull << 23);
  if (!parsed.document) throw InputError("cannot read '" + map_file.string() + "' again: " + parsed.why_not);
  json document = *parsed.document;

  LocalizerOptions localizer_options = FollowMap(opened, options.localizer, QueryResize(map, ""));
  localizer_options.Check();
  Localizer localizer(map, opened.keys, *opened.matcher, localizer_options);

  AddExperienceSummary summary;
  summary.num_key_images = static_cast<int>(map.key_images.size());
  summary.experience.id = static_cast<int>(opened.experiences.size()) + 1;
  summary.experience.source = source_path;
  const std::string folder = fmt::format("{}/{}", kExperiencesDirectory, summary.experience.id);

  Undo undo;
  const fs::path experiences_directory = map_directory / kExperiencesDirectory;
  std::error_code ec;
  if (fs::create_directory(experiences_directory, ec)) undo.Add(experiences_directory);
  if (ec) {
    throw InputError("cannot create '" + experiences_directory.string() + "' (" + ec.message() +
                     "); check the permissions of the map directory");
  }
  auto views_directory = std::make_unique<AtomicOutputDirectory>(map_directory / folder, OutputPolicy());
  const auto view_file = [](int key) { return fmt::format("{:06d}.png", key); };

  ExperienceViewPicker picker(summary.num_key_images);
  const cv::Size map_size = map.input.frame_size;
  const LocalizationSummary run = LocalizeSequence(
      source, *opened.matcher, localizer, options.run, [&](const Frame& frame, const LocalizationResult& result) {
        if (map_size.area() > 0 && frame.gray.size() != map_size) {
          throw InputError(
              fmt::format("'{}' has frames of {}, the map '{}' key images of {}: an experience's views "
                          "must be of the map's size; give --resize {}",
                          source_path, SizeText(frame.gray.size()), map_directory.string(), SizeText(map_size),
                          SizeText(map_size)));
        }
        for (int key : picker.Offer(result)) {
          const fs::path file = views_directory->path() / view_file(key);
          if (!cv::imwrite(file.string(), ColorImage(frame))) {
            throw InputError("cannot write '" + file.string() +
                             "'; check the free space and the permissions of the "
                             "map directory");
          }
        }
      });
  summary.frames = run.frames;
  summary.lost = run.lost;
  summary.experience.views = picker.Views();
  if (summary.experience.views.empty()) {
    throw InputError(
        fmt::format("no frame of '{}' localized at a key image of the map '{}' ({} frames): nothing "
                    "added; is it a run of the same route?",
                    source_path, map_directory.string(), run.frames));
  }
  for (ExperienceView& v : summary.experience.views) v.image_file = folder + "/" + view_file(v.key);

  // The new files first, map.json last: a map.json never names a view that is not there.
  views_directory->Commit();
  undo.Add(map_directory / folder);
  json list = document.contains("experiences") ? document["experiences"] : json::array();
  list.push_back(ExperiencesToJson({summary.experience}).at(0));
  document["experiences"] = std::move(list);
  WriteFileAtomically(map_file, document.dump(1) + "\n");
  undo.Dismiss();
  return summary;
}

}  // namespace vmap
