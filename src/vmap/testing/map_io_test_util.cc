#include "vmap/testing/map_io_test_util.h"

#include <fstream>

#include <opencv2/imgcodecs.hpp>

#include "vmap/core/error.h"
#include "vmap/map/map_io.h"

namespace vmap::testing {

VisualMap SmallMap(const std::filesystem::path& directory) {
  VisualMap map;
  map.input.path = "video.mp4";
  map.input.format = SourceFormat::kVideo;
  map.input.frame_size = {64, 48};
  map.options_json = R"({"tau": 0.5, "quality_mean": "arithmetic"})";
  map.num_frames = 20;
  std::filesystem::create_directories(directory / "keys");
  for (int f : {0, 9, 19}) {
    KeyImage k;
    k.frame_index = f;
    k.source_index = f;
    k.timestamp = f / 30.0;
    k.source_name = "frame_" + std::to_string(f);
    k.image_file = "keys/" + std::to_string(f) + ".png";
    cv::imwrite((directory / k.image_file).string(), cv::Mat(48, 64, CV_8U, cv::Scalar(f)));
    map.key_images.push_back(k);
  }
  for (int i = 0; i < 2; ++i) {
    Link l;
    l.from_key = i;
    l.to_key = i + 1;
    l.num_tentative = 3;
    l.num_verified = 2;
    l.similarity = 2.0 / 3.0;
    l.has_fundamental = true;
    l.F = cv::Matx33d(0, -1e-3, 0.1 * i, 1e-3, 0, -0.2, -0.1, 0.2, 1);
    for (int c = 0; c < 3; ++c) l.correspondences.push_back({{1.5f * c, 2.f + i}, {3.25f * c, 4.f}});
    map.links.push_back(l);
  }
  map.evaluations = {{0, 1, 0.9, 10, 9, true}, {0, 2, 0.0, 3, 0, false}};
  map.quality = 0.42;
  return map;
}

void WriteText(const std::filesystem::path& file, const std::string& text) { std::ofstream(file) << text; }

std::string ReadMapError(const std::filesystem::path& directory) {
  try {
    ReadMap(directory);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace vmap::testing
