#pragma once
// A KITTI odometry image's frame number, read from its file name: image_0/000123.png is frame 123, the
// image of line 123 of times.txt and of poses.txt. Pairing by the number and not by the position in the
// folder's listing keeps every image at its own time and pose when images of the sequence are missing.

#include <optional>
#include <string>

namespace vmap {

// The number of a file named by digits alone ("000123.png", "7.jpg"): nullopt for any other name, or a
// number beyond a billion frames.
std::optional<int> KittiFrameNumber(const std::string& file_name);

}  // namespace vmap
