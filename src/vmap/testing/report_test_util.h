#pragma once
// Test helpers: synthetic map directories (rendered with OpenCV, no matcher needed), temporary folders and
// the SVG parsing that maps plotted points back to data values.

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/map/visual_map.h"
#include "vmap/testing/scoped_temp_dir.h"  // ReadText

namespace vmap::report_test {

using testing::ReadText;

struct SyntheticMapOptions {
  int num_frames = 40;
  int frames_per_key = 9;
  cv::Size frame_size{320, 240};
  std::vector<int> below_tau_links = {2};
  double tau = 0.35;
};

// Renders frames sliding over a textured scene, chooses key images, links them with correspondences
// (verified ones follow the true shift, rejected ones do not) and records an evaluation per frame. Writes
// map.json, correspondences.bin and keys/*.png into `directory` (created) and returns the map.
VisualMap WriteSyntheticMap(const std::filesystem::path& directory, const SyntheticMapOptions& options = {});

// Every value of attribute `name` in `html`, in order.
std::vector<std::string> AttributeValues(const std::string& html, const std::string& name);

// How often `needle` occurs in `haystack`.
int CountOccurrences(const std::string& haystack, const std::string& needle);

// The text of the element starting with `<svg ... id="id"` up to its </svg>.
std::string SvgById(const std::string& html, const std::string& id);

// Maps a plot's pixel coordinates back to data values using the axis attributes the plot carries.
struct PlotAxes {
  double x_min, x_max, y_min, y_max, left, right, top, bottom;
  cv::Point2d ToData(const cv::Point2d& pixel) const;
};
PlotAxes ParsePlotAxes(const std::string& svg);

// The points of every <polyline> whose opening tag contains `marker` (e.g. data-key-frame="9"), in data units.
std::vector<cv::Point2d> PolylinePoints(const std::string& svg, const std::string& marker, const PlotAxes& axes);
// The centres of every <circle> whose opening tag contains `marker`, in data units.
std::vector<cv::Point2d> CircleCentres(const std::string& svg, const std::string& marker, const PlotAxes& axes);

}  // namespace vmap::report_test
