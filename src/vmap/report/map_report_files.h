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

// Writes the key-image thumbnails, the route video and the match figures into `directory` (report/ while
// it is being written).
MapReportFiles WriteMapReportFiles(const std::filesystem::path& map_directory, const VisualMap& map,
                                   const MapReportOptions& options, const std::filesystem::path& directory);

}  // namespace vmap::report
