#pragma once
// Adding a repeat run to a map as another experience of its route (map/experiences.h):
// `vmap build REPEAT --add-experience-to MAP`. The run is localized against the map as `vmap localize` does;
// each key image gains as its view the repeat frame that localized at it best (most verified matches), with
// that frame's heading against it. The key images, links and every other file of the map stay as they were.
//
// Atomic: the views are written into a folder of the run's own inside the map, moved to MAP/experiences/<id>/
// once complete, and map.json is replaced last (core/atomic_output); when anything fails, or the run is
// interrupted, what was moved is removed again, so the map is left as it was. Writers of one map exclude each
// other (core/directory_lock.h): a second add waits for the first, then adds the next experience. Nothing is
// written through a symbolic link inside the map. The map's key-image cache (localization_cache.bin) is
// neither read nor written: the new map.json makes it stale anyway.

#include <filesystem>
#include <string>
#include <vector>

#include "vmap/features/matcher_options_json.h"
#include "vmap/localization/localize_sequence.h"
#include "vmap/localization/localizer.h"
#include "vmap/map/experiences.h"
#include "vmap/sources/frame_source.h"

namespace vmap {

struct AddExperienceOptions {
  // How the run is localized; its verifier, S, translation thresholds and camera follow the map (FollowMap).
  LocalizerOptions localizer;
  LocalizeSequenceOptions run;

  // "localizer" (but its verifier and translation thresholds, which follow the map) and "run".
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

// Keeps, for every key image, the frame of a run that localized at it best.
class ExperienceViewPicker {
 public:
  explicit ExperienceViewPicker(int num_keys);
  // Offers a frame's result: its accepted comparisons with `key` and `next_key` that have a heading. Returns
  // the key images for which the frame is now the best view (more verified matches than any frame before; the
  // earlier frame on ties).
  std::vector<int> Offer(const LocalizationResult& result);
  // The best view of each key image that has one, in key order (image_file left empty).
  std::vector<ExperienceView> Views() const;

 private:
  std::vector<ExperienceView> best_;  // num_verified 0: none yet
};

struct AddExperienceSummary {
  Experience experience;  // as added to map.json
  long frames = 0;        // frames of the run localized
  long lost = 0;          // of them, lost
  int num_key_images = 0;
};

// Adds the frames of `source` (the repeat run; `source_path` is recorded) to the map in `map_directory`.
// Throws InputError, leaving the map as it was, when the map cannot be read, the frames are not of the map's
// frame size, or no frame localized at any key image. `matcher_run`: where the map's matcher computes and the weights
// it reads in this run (CreateMapMatcher).
AddExperienceSummary AddExperience(const std::filesystem::path& map_directory, FrameSource& source,
                                   const std::string& source_path, const AddExperienceOptions& options,
                                   const MatcherRunSettings& matcher_run = {});

}  // namespace vmap
