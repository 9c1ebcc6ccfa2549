#pragma once
// Experiences: other runs of the same route added to a map (`vmap build REPEAT --add-experience-to MAP`).
// Each key image of the teach run may gain one view per experience: the repeat frame that localized at it
// best. Localization then compares a frame with a key image's views too and keeps the one that fits best
// (across seasons, a view from a similar season verifies where the teach image does not). The teach run's key
// images and links are never changed by an experience.
//
// map.json holds them in an `experiences` array (absent in maps without any):
//   {"id": 1, "source": "<input path>", "views": [
//     {"key": 3, "image": "experiences/1/000003.png", "frame_index": 12, "source_index": 12,
//      "timestamp": null, "source_name": "0304.png", "heading_px": -12.5, "verified": 87}, ...]}
// `heading_px` is the view's heading against its key image (x in the view minus x in the key image, as
// geometry/heading.h): a frame's heading against the key image is its heading against the view plus this.

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace vmap {

struct VisualMap;

// One repeat frame stored as a view of a teach key image.
struct ExperienceView {
  int key = 0;              // index into VisualMap::key_images
  std::string image_file;   // relative to the map directory: experiences/<id>/<frame>.png
  int frame_index = 0;      // the frame's index in the repeat run
  int source_index = 0;     // its index in the repeat run's input
  double timestamp = -1.0;  // seconds; -1 when the input has none
  std::string source_name;  // the frame's file name, or "frame_000123"
  double heading_px = 0.0;  // x in the view minus x in the key image (finite)
  int num_verified = 0;     // verified matches of the view with the key image when it was chosen
};

struct Experience {
  int id = 1;                         // 1, 2, ... in the order added; 0 names the teach run
  std::string source;                 // the repeat run's input, as given
  std::vector<ExperienceView> views;  // at most one per key image, in key order
};

inline constexpr const char* kExperiencesDirectory = "experiences";

// The `experiences` array of map.json.
nlohmann::json ExperiencesToJson(const std::vector<Experience>& experiences);

// Reads and checks map.json's `experiences` (`value`) against the map read so far: ReadMap's reader of them,
// the one every command uses (key indices in range,
// finite headings, ids 1, 2, ... in order, each view's image a PNG or JPEG of the map's frame size inside the
// map directory). Throws InputError naming `map_file` and the field.
std::vector<Experience> ExperiencesFromJson(const nlohmann::json& value, const VisualMap& map,
                                            const std::filesystem::path& directory,
                                            const std::filesystem::path& map_file);

}  // namespace vmap
