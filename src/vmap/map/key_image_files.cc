// The key image files of a map: their size read from the header, and their reading, checked again as ReadMap checked
// them because a map read earlier may have changed on disk since.

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/core/image_decode.h"
#include "vmap/core/image_header.h"
#include "vmap/map/map_files.h"
#include "vmap/map/map_io.h"
#include "vmap/map/map_json_fields.h"
#include "vmap/sources/frame_source.h"

namespace vmap {
namespace fs = std::filesystem;

std::string internal::KeyImageSizeProblem(const std::optional<cv::Size>& size, const cv::Size& frame_size) {
  if (!size) return "is not a PNG or JPEG image";
  const bool fits =
      frame_size.empty() ? static_cast<long>(size->width) * size->height <= kMaxFramePixels : *size == frame_size;
  if (fits) return "";
  return fmt::format("is {}x{}, {}", size->width, size->height,
                     frame_size.empty()
                         ? std::string("more pixels than a frame")
                         : fmt::format("not the map's frame size {}x{}", frame_size.width, frame_size.height));
}

std::optional<cv::Size> KeyImageFileSize(const fs::path& file) {
  std::string why_not;
  // The input's own file, wherever it is: a folder of links to a recording's images gives the map its files, as the
  // folder of the images does (ReadMap checks the copy inside the map).
  const std::optional<ContainedFile> opened = ContainedFile::OpenRegular(file, &why_not);
  if (!opened) return std::nullopt;
  return ImageHeaderSize(*opened);
}

namespace {

// The key image's file, opened inside the map directory, or the InputError that says why it cannot be.
ContainedFile OpenKeyImage(const fs::path& map_directory, const KeyImage& key) {
  if (!IsPlainRelativePath(key.image_file)) {
    internal::Malformed(map_directory / kMapFileName,
                        "key image '" + key.image_file + "' points outside the map directory");
  }
  return internal::OpenMapFile(map_directory, key.image_file, "key image", map_directory / kMapFileName, "key image");
}

}  // namespace

fs::path KeyImageFile(const fs::path& map_directory, const KeyImage& key) {
  return OpenKeyImage(map_directory, key).path();
}

cv::Mat ReadKeyImage(const fs::path& map_directory, const KeyImage& key, bool grayscale, const cv::Size& frame_size) {
  const ContainedFile opened = OpenKeyImage(map_directory, key);
  const fs::path& file = opened.path();
  // The map reader checked this file, but it may have been replaced or rewritten since (a map rebuilt into the same
  // folder while a program holds the old one): its header is checked again before anything is read, and what is
  // decoded is the bytes read once.
  const auto changed = [&file](const std::string& problem) {
    return InputError("key image '" + file.string() + "' " + problem +
                      ": it changed since the map was read; read the map again, or rebuild it with `vmap build`");
  };
  if (std::string problem = internal::KeyImageSizeProblem(ImageHeaderSize(opened), frame_size); !problem.empty()) {
    throw changed(problem);
  }
  std::string why_not;
  const cv::Mat image = DecodeImageFile(opened, grayscale ? cv::IMREAD_GRAYSCALE : cv::IMREAD_COLOR,
                                        frame_size.empty() ? kMaxFramePixels : frame_size.area(), &why_not);
  if (image.empty())
    throw InputError("key image '" + file.string() + "' " + why_not + "; rebuild the map with `vmap build`");
  if (!frame_size.empty() && image.size() != frame_size) {
    throw changed(fmt::format("is {}x{}, not the map's frame size {}x{}", image.cols, image.rows, frame_size.width,
                              frame_size.height));
  }
  return image;
}

}  // namespace vmap
