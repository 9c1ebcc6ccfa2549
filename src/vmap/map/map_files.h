#pragma once
// Opening a map's files under reading, shared by the map reader (map_io.cc) and the key image reader
// (key_image_files.cc), so that both say the same thing about the same fault. Internal to map/.

#include <filesystem>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "vmap/core/contained_file.h"

namespace vmap::internal {

// Opens `relative` inside the map `directory`, or throws the InputError that fits why it cannot be: missing (rebuild
// the map), leading outside it or not a regular file (malformed: `map_json`'s `field` names it, or the file itself
// when `field` is empty), or unreadable by this user or process (the permissions, or ulimit -n). `what` names the
// file in the message ("key image"), or nothing.
ContainedFile OpenMapFile(const std::filesystem::path& directory, const std::string& relative, const std::string& what,
                          const std::filesystem::path& map_json, const std::string& field);

// Why a key image whose header announces `size` (nullopt: neither PNG nor JPEG) is not one of a map whose frames are
// `frame_size` (empty: a map that does not record it, whose key images may have at most a frame's pixels), or "": read
// before anything is decoded.
std::string KeyImageSizeProblem(const std::optional<cv::Size>& size, const cv::Size& frame_size);

}  // namespace vmap::internal
