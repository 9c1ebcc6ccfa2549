#pragma once
// The HTML report of a map or of a threshold sweep: one page that opens offline in any browser and makes
// no network request (inline CSS, SVG and script; images as relative files loaded lazily).
//
// A map's report lives inside the map directory:
//   report.html                 the page
//   report/keys/NNNNNN.jpg      a thumbnail per key image (NNNNNN = key-image index)
//   report/links/NNNNNN.jpg     the match figure of each link (NNNNNN = link index)
//   report/route.mp4            the route preview: the key images in order (route.webm without H.264)
// Both are replaced atomically: an interrupted run leaves the previous report intact.

#include <filesystem>
#include <string>

#include <opencv2/core.hpp>

#include "vmap/core/option_fields.h"
#include "vmap/map/visual_map.h"
#include "vmap/mapping/batch_build.h"
#include "vmap/report/match_figure.h"

namespace vmap {

inline constexpr const char* kReportFileName = "report.html";
inline constexpr const char* kReportAssetsDirectory = "report";

struct MapReportOptions {
  int thumbnail_width = 320;  // key-image strip
  int figure_width = 960;     // match figures (two images of about 480 px)
  int jpeg_quality = 85;
  bool route_video = true;  // report/route.mp4 (or .webm): the key images in order
  double route_fps = 3.0;   // key images per second in the route video

  // The flags of `vmap report` (--thumbnail-width, --figure-width, --no-video); the rest have none.
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

// Reads the map in `map_directory` (ReadMap) and writes report.html and report/ into it. Throws InputError
// when the map is missing, malformed or incomplete; writes nothing then, and never outside the directory.
void WriteMapReport(const std::filesystem::path& map_directory);
void WriteMapReport(const std::filesystem::path& map_directory, const MapReportOptions& options);

// Writes report.html for a sweep into `directory` (which must exist): the paper-style table with the
// best tau marked, key images and Q against tau, and links to the per-tau maps that were written.
void WriteSweepReport(const SweepResult& sweep, const std::filesystem::path& directory);

// "key 3 (frame 120) -> key 4 (frame 161)": the title of link `link_index` in figures.
std::string LinkTitle(const VisualMap& map, int link_index);

// The match figure of one link of a map read from `map_directory`.
cv::Mat DrawMapLink(const std::filesystem::path& map_directory, const VisualMap& map, int link_index,
                    const MatchFigureOptions& options = {});

}  // namespace vmap
