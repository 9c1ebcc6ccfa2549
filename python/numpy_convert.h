#pragma once
// numpy arrays to and from what the library takes: images (cv::Mat) and small matrices.

#include <string>

#include <opencv2/core.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

namespace vmap::python {

// An image given from Python: uint8, HxW (grey) or HxWxC with C 3 (BGR, as OpenCV gives it) or 4 (BGRA).
// `image` is a header over `pixels` (the array itself when it is C-contiguous, no copy).
struct ImageInput {
  pybind11::array pixels;
  cv::Mat image;
};
// Anything but such an array is a vmap.Error naming `what` (vmap.ArgumentTypeError for what is no array), and so
// is an image of a size vmap refuses (FrameSizeProblem): checked before any copy.
ImageInput ImageView(const pybind11::object& object, const std::string& what);

// A copy of an 8-bit image: HxW, or HxWxC for C > 1 channels.
pybind11::array_t<std::uint8_t> ImageArray(const cv::Mat& image);

// A 3x3 float64 array; None for a matrix that is not set.
pybind11::object MatrixArray(const cv::Matx33d& m, bool valid = true);
pybind11::object VectorArray(const cv::Vec3d& v, bool valid = true);

}  // namespace vmap::python
