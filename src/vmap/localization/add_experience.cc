#include "vmap/localization/add_experience.h"

#include <cmath>
#include <memory>
#include <system_error>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "vmap/core/atomic_output.h"
#include "vmap/core/contained_file.h"
#include "vmap/core/directory_lock.h"
#include "vmap/core/error.h"
#include "vmap/core/image_file.h"
#include "vmap/core/output_file.h"
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

}  // namespace

AddExperienceSummary AddExperience(const fs::path& map_directory, FrameSource& source, const std::string& source_path,
                                   const AddExperienceOptions& options, const MatcherRunSettings& matcher_run) {
  options.Check();
  // Another writer of this map (another add, a `build -o` replacing it) finishes first; the map is read only
  // once this one holds the lock, so that the experience it adds is numbered after the others and no other
  // writer's map.json is written over with a copy that lacks their work.
  const DirectoryWriteLock lock(map_directory, "the map");
  const fs::path& map_path = lock.path();  // its real path: nothing below is written through a link
  // A build started before this add replaces the map once it ends, without the experience: it said it was added,
  // and was gone (the build claims the folder only when it puts its map in place).
  if (const long builder = OtherWriterOf(map_path); builder != 0) {
    throw InputError(
        fmt::format("'{}' is being rebuilt by vmap process {}, which will replace the map and drop what is "
                    "added to it now: add the experience once that build has finished",
                    map_path.string(), builder));
  }
  // map.json is replaced at the end: one that may not be (read-only, a link) refuses the run before the work.
  CheckOutputFiles({{map_path / kMapFileName, "the map's map.json"}}, {});
  KeyImageStoreOptions store_options;
  store_options.use_cache = false;
  store_options.thumbnail_width = options.localizer.ranking.thumbnail_width;
  const LocalizationMap opened = OpenLocalizationMap(map_path, store_options, matcher_run);
  const VisualMap& map = opened.map;
  const fs::path map_file = map_path / kMapFileName;
  // map.json as it is now: everything but `experiences` is written back as it was.
  const ContainedJson parsed = ReadContainedJson(map_path, kMapFileName, kMaxMapJsonBytes, kMaxMapJsonValues);
  if (!parsed.document) throw InputError("cannot read '" + map_file.string() + "' again: " + parsed.why_not);
  json document = *parsed.document;

  LocalizerOptions localizer_options = FollowMap(opened, options.localizer, QueryResize(map, ""));
  localizer_options.Check();
  Localizer localizer(map, opened.keys, *opened.matcher, localizer_options);

  AddExperienceSummary summary;
  summary.num_key_images = static_cast<int>(map.key_images.size());
  summary.experience.id = static_cast<int>(opened.experiences.size()) + 1;
  summary.experience.source = source_path;
  const std::string id = std::to_string(summary.experience.id);
  const std::string folder = std::string(kExperiencesDirectory) + "/" + id;
  const fs::path experiences_directory = map_path / kExperiencesDirectory;
  // Refused before any work: an `experiences` that is not a real folder of the map, or an experience folder
  // that map.json does not list (left by an add killed between moving it in and writing map.json).
  std::error_code ec;
  const fs::file_status experiences_status = fs::symlink_status(experiences_directory, ec);
  if (fs::exists(experiences_status) && !fs::is_directory(experiences_status)) {
    throw InputError("'" + experiences_directory.string() +
                     "' is not a folder (a symbolic link, or a file): vmap writes nothing through a link in a map; "
                     "move it away");
  }
  if (fs::exists(fs::symlink_status(map_path / folder, ec))) {
    throw InputError("'" + (map_path / folder).string() + "' exists but map.json lists no experience " + id +
                     " (left by an add that was killed?); move it away and add again");
  }

  // The views are written into a folder of this run's own (".experiences.partial-PID-N" in the map), removed
  // if the run fails or is interrupted, and by the next add when it was killed outright. The map's own
  // `experiences` folder appears, or gains `id`, only once every view is written.
  TemporaryDirectory views(experiences_directory);
  const fs::path views_directory = views.path() / id;
  if (!fs::create_directory(views_directory, ec) || ec) {
    throw InputError("cannot create '" + views_directory.string() + "' (" + ec.message() +
                     "); check the permissions of the map directory");
  }
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
          const fs::path file = views_directory / view_file(key);
          WriteImageFile(file, ColorImage(frame), "the view");
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

  // The new files first, map.json last: a map.json never names a view that is not there, and until map.json
  // is written the views are this run's to remove (on failure, on an interruption).
  if (fs::exists(fs::symlink_status(experiences_directory, ec))) {
    views.MoveTo(views_directory, map_path / folder);
  } else {
    views.MoveTo(views.path(), experiences_directory);
  }
  json list = document.contains("experiences") ? document["experiences"] : json::array();
  list.push_back(ExperiencesToJson({summary.experience}).at(0));
  document["experiences"] = std::move(list);
  WriteFileAtomically(map_file, document.dump(1) + "\n", {&views});
  return summary;
}

}  // namespace vmap
