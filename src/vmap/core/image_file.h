#pragma once
// Images written to files with every step checked. cv::imwrite is not: OpenCV 4.6 reports success when the disk
// fills at its last flush, which once left a key image cut short in a map that `vmap build` committed with exit 0
// (and the good map it replaced was gone). Here the image is encoded in memory and its bytes written, closed and
// checked like any other output.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

namespace vmap {

// Encodes `image` by the extension of `path` (".png", ".jpg"; OpenCV's `params`) and writes it to `path`,
// replacing a file there. Throws InputError "cannot write WHAT 'PATH' (REASON); HINT" when encoding, writing or
// closing fails (the reason as the system says it: "No space left on device"); the partial file is removed.
void WriteImageFile(const std::filesystem::path& path, const cv::Mat& image, const std::string& what,
                    const std::vector<int>& params = {});

// Writes `bytes` (an encoded image) to `path` the same way, with the same errors.
void WriteImageBytes(const std::filesystem::path& path, std::string_view bytes, const std::string& what);

// Copies the encoded image `source` to `path` the same way (std::filesystem::copy_file says "Input/output error"
// where the disk is full).
void CopyImageFile(const std::filesystem::path& source, const std::filesystem::path& path, const std::string& what);

}  // namespace vmap
