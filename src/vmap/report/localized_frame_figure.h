#pragma once
// A localized frame beside the images it was compared with: its key image and the next, or the views of the experiences
// that fit them best, each labelled with S and the verified count (the localization report's figures).

#include <filesystem>
#include <string>

#include <opencv2/core.hpp>

#include "vmap/localization/localization_result.h"
#include "vmap/map/visual_map.h"

namespace vmap::report {

// The image a frame was compared with at a key image, and its label: the teach run's key image, or the view of the
// experience that fit best, which the frame's S was measured against.
struct ComparedImage {
  cv::Mat image;
  std::string label;  // " (experience 2)" for a view, "" for the key image
};

// `key`: the frame's key (or next key) image; `c`: its comparison with it, which a frame may lack (its key image
// tracked without one: c.key -1), and then names no view. Throws InputError when the image cannot be read.
ComparedImage ReadComparedImage(const std::filesystem::path& map_directory, const VisualMap& map, int key,
                                const KeyComparison& c);

// The frame, its key image and the next key image side by side, each labelled, at most `width` pixels wide; a red
// frame when lost.
cv::Mat DrawLocalizedFrame(const cv::Mat& frame, const ComparedImage& key, const ComparedImage& next,
                           const LocalizationResult& r, int width);

}  // namespace vmap::report
