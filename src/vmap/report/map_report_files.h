#pragma once
// The files of a map's report beside its page (report/html_report.h): a thumbnail per key image, the route
// video and a match figure per link.

#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/map/visual_map.h"
#include "vmap/report/html_report.h"

namespace vmap::report {

// What WriteMapReportFiles wrote into report/, for the page to show.
struct MapReportFiles {
  std::vector<cv::Size> thumbnail_sizes;  // per key image: report/keys/NNNNNN.jpg
  std::vector<cv::Size> figure_sizes;     // per link: report/links/NNNNNN.jpg
  std::string video_file;                 // the route video in report/; empty when none was written
  cv::Size video_size;
};

// The names of the entries WriteMapReportFiles writes: the thumbnails' folder, the figures' folder, the route
// video under either of its names.
inline constexpr const char* kThumbnailsFolder = "keys";
inline constexpr const char* kMatchFiguresFolder = "links";
inline constexpr const char* kRouteVideoNames[] = {"route.mp4", "route.webm"};

// A key image's thumbnail and a link's match figure as named inside report/ ("keys/000012.jpg"): where
// WriteMapReportFiles writes them and what the page links to.
std::string ThumbnailFile(int key);
std::string MatchFigureFile(int link);

// Whether an entry of report/, by its name, is one the report writes: a new report replaces those and keeps what
// else a user put there.
bool IsMapReportFile(const std::string& name);

// Writes the key-image thumbnails, the route video and the match figures into `directory` (report/ while
// it is being written).
MapReportFiles WriteMapReportFiles(const std::filesystem::path& map_directory, const VisualMap& map,
                                   const MapReportOptions& options, const std::filesystem::path& directory);

}  // namespace vmap::report
