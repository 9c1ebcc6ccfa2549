#include "vmap/testing/report_test_util.h"

#include <stdlib.h>

#include <fstream>
#include <sstream>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "vmap/map/map_io.h"

namespace vmap::report_test {
namespace fs = std::filesystem;

namespace {

constexpr int kShiftPerFrame = 6;  // pixels the camera slides between frames

cv::Mat RenderScene(const cv::Size& frame_size, int num_frames) {
  cv::Mat scene(frame_size.height, frame_size.width + kShiftPerFrame * num_frames, CV_8UC3, cv::Scalar(235, 230, 220));
  cv::RNG rng(7);
  for (int i = 0; i < scene.cols / 3; ++i) {
    const cv::Point centre(rng.uniform(0, scene.cols), rng.uniform(0, scene.rows));
    const cv::Scalar colour(rng.uniform(0, 256), rng.uniform(0, 256), rng.uniform(0, 256));
    if (i % 2) {
      cv::circle(scene, centre, rng.uniform(3, 18), colour, cv::FILLED, cv::LINE_AA);
    } else {
      cv::rectangle(scene, cv::Rect(centre, cv::Size(rng.uniform(4, 30), rng.uniform(4, 30))), colour, cv::FILLED);
    }
  }
  return scene;
}

}  // namespace

VisualMap WriteSyntheticMap(const fs::path& directory, const SyntheticMapOptions& options) {
  fs::create_directories(directory / "keys");
  const cv::Mat scene = RenderScene(options.frame_size, options.num_frames);
  auto frame_at = [&](int index) {
    return scene(cv::Rect(index * kShiftPerFrame, 0, options.frame_size.width, options.frame_size.height)).clone();
  };

  VisualMap map;
  map.input.path = "synthetic/slide";
  map.input.format = SourceFormat::kImageFolder;
  map.input.native_size = map.input.frame_size = options.frame_size;
  map.options_json = R"({"matcher":{"name":"orb","features":2000},"verifier":{"method":"magsac","threshold":0.5},)"
                     R"("tau":)" +
                     std::to_string(options.tau) + R"(,"quality_mean":"arithmetic"})";
  map.num_frames = options.num_frames;
  map.seconds = 1.5;

  std::vector<int> key_frames;
  for (int f = 0; f < options.num_frames; f += options.frames_per_key) key_frames.push_back(f);
  if (key_frames.back() != options.num_frames - 1) key_frames.push_back(options.num_frames - 1);
  for (size_t i = 0; i < key_frames.size(); ++i) {
    KeyImage k;
    k.frame_index = k.source_index = key_frames[i];
    k.timestamp = i % 2 ? key_frames[i] * 0.1 : -1.0;  // both with and without timestamps
    k.source_name = "frame_" + std::to_string(key_frames[i]) + ".png";
    char name[32];
    std::snprintf(name, sizeof(name), "keys/%06d.png", key_frames[i]);
    k.image_file = name;
    k.num_features = 500;
    k.reason = i == 0 ? "first frame" : "similarity drop";
    cv::imwrite((directory / k.image_file).string(), frame_at(key_frames[i]));
    map.key_images.push_back(k);
  }

  cv::RNG rng(11);
  for (size_t i = 0; i + 1 < key_frames.size(); ++i) {
    Link l;
    l.from_key = static_cast<int>(i);
    l.to_key = static_cast<int>(i + 1);
    const float shift = static_cast<float>(kShiftPerFrame * (key_frames[i + 1] - key_frames[i]));
    const int verified = 30 + 5 * static_cast<int>(i), rejected = 12;
    for (int v = 0; v < verified; ++v) {
      const cv::Point2f p0(rng.uniform(shift, options.frame_size.width - 1.0f),
                           rng.uniform(0.0f, options.frame_size.height - 1.0f));
      l.correspondences.push_back({p0, p0 - cv::Point2f(shift, 0.0f)});
    }
    for (int r = 0; r < rejected; ++r) {
      l.correspondences.push_back({cv::Point2f(rng.uniform(0.0f, 319.0f), rng.uniform(0.0f, 239.0f)),
                                   cv::Point2f(rng.uniform(0.0f, 319.0f), rng.uniform(0.0f, 239.0f))});
    }
    l.num_verified = verified;
    l.num_tentative = verified + rejected;
    l.similarity = static_cast<double>(verified) / l.num_tentative;
    l.has_fundamental = true;
    l.F = cv::Matx33d(0, 0, 0, 0, 0, -1, 0, 1, 0);
    for (int b : options.below_tau_links) l.below_tau = l.below_tau || b == static_cast<int>(i);
    map.links.push_back(l);
    for (int f = key_frames[i] + 1; f <= key_frames[i + 1]; ++f) {
      Evaluation e;
      e.key_frame = key_frames[i];
      e.frame = f;
      e.matched = !(i == 1 && f == key_frames[i] + 2);  // one failed comparison
      e.similarity = e.matched ? 1.0 - 0.07 * (f - key_frames[i]) : 0.0;
      e.num_tentative = 100;
      e.num_verified = static_cast<int>(100 * e.similarity);
      map.evaluations.push_back(e);
    }
  }
  map.quality = ComputeStatistics(map, QualityMean::kArithmetic).quality;
  WriteMapFiles(map, directory);
  return map;
}

std::vector<std::string> AttributeValues(const std::string& html, const std::string& name) {
  std::vector<std::string> values;
  const std::string needle = " " + name + "=\"";
  for (size_t at = html.find(needle); at != std::string::npos; at = html.find(needle, at + 1)) {
    const size_t begin = at + needle.size();
    values.push_back(html.substr(begin, html.find('"', begin) - begin));
  }
  return values;
}

int CountOccurrences(const std::string& haystack, const std::string& needle) {
  int count = 0;
  for (size_t at = haystack.find(needle); at != std::string::npos; at = haystack.find(needle, at + needle.size())) {
    ++count;
  }
  return count;
}

std::string SvgById(const std::string& html, const std::string& id) {
  const size_t id_at = html.find("id=\"" + id + "\"");
  if (id_at == std::string::npos) return "";
  const size_t begin = html.rfind("<svg", id_at);
  const size_t end = html.find("</svg>", id_at);
  return html.substr(begin, end + 6 - begin);
}

namespace {

double Attribute(const std::string& tag, const std::string& name) {
  const std::vector<std::string> values = AttributeValues(tag, name);
  if (values.empty()) throw std::runtime_error("no attribute " + name);
  return std::stod(values.front());
}

}  // namespace

cv::Point2d PlotAxes::ToData(const cv::Point2d& pixel) const {
  return {x_min + (pixel.x - left) / (right - left) * (x_max - x_min),
          y_min + (bottom - pixel.y) / (bottom - top) * (y_max - y_min)};
}

PlotAxes ParsePlotAxes(const std::string& svg) {
  const std::string tag = svg.substr(0, svg.find('>'));
  return {Attribute(tag, "data-x-min"), Attribute(tag, "data-x-max"), Attribute(tag, "data-y-min"),
          Attribute(tag, "data-y-max"), Attribute(tag, "data-left"),  Attribute(tag, "data-right"),
          Attribute(tag, "data-top"),   Attribute(tag, "data-bottom")};
}

std::vector<cv::Point2d> PolylinePoints(const std::string& svg, const std::string& marker, const PlotAxes& axes) {
  std::vector<cv::Point2d> points;
  for (size_t at = svg.find("<polyline"); at != std::string::npos; at = svg.find("<polyline", at + 1)) {
    const std::string tag = svg.substr(at, svg.find('>', at) - at);
    if (tag.find(marker) == std::string::npos) continue;
    std::istringstream list(AttributeValues(tag, "points").at(0));
    std::string pair;
    while (list >> pair) {
      const size_t comma = pair.find(',');
      points.push_back(axes.ToData({std::stod(pair.substr(0, comma)), std::stod(pair.substr(comma + 1))}));
    }
  }
  return points;
}

std::vector<cv::Point2d> CircleCentres(const std::string& svg, const std::string& marker, const PlotAxes& axes) {
  std::vector<cv::Point2d> points;
  for (size_t at = svg.find("<circle"); at != std::string::npos; at = svg.find("<circle", at + 1)) {
    const std::string tag = svg.substr(at, svg.find('>', at) - at);
    if (tag.find(marker) == std::string::npos) continue;
    points.push_back(axes.ToData({Attribute(tag, "cx"), Attribute(tag, "cy")}));
  }
  return points;
}

}  // namespace vmap::report_test
