#include "numpy_convert.h"

#include <cstring>
#include <limits>

#include "vmap/core/error.h"
#include "vmap/sources/frame_source.h"

#include "argument_errors.h"

namespace py = pybind11;

namespace vmap::python {

ImageInput ImageView(const py::object& object, const std::string& what) {
  if (!py::isinstance<py::array>(object)) {
    throw ArgumentTypeError(what + " is a " + TypeName(object) +
                            ", not a numpy array; give a uint8 image (HxW grey or HxWx3 BGR)");
  }
  const py::array array = py::reinterpret_borrow<py::array>(object);
  // By kind and size, not by the dtype object: an array that went through pickle (a multiprocessing queue) has an
  // equal dtype of its own, and pybind11 2.10 has no dtype equality.
  if (array.dtype().kind() != 'u' || array.dtype().itemsize() != 1) {
    // A type, as numpy's own casting errors are; the conversion depends on the values' range, which astype alone
    // does not scale (a float image in [0, 1] would become black).
    const char kind = array.dtype().kind();
    const std::string conversion = kind == 'f' ? "(image * 255).clip(0, 255).astype(numpy.uint8) for values in [0, 1], "
                                                 "image.clip(0, 255).astype(numpy.uint8) for values in [0, 255]"
                                   : kind == 'b'
                                       ? "image.astype(numpy.uint8) * 255"
                                       : "scaled to 0..255 first, e.g. (image >> 8).astype(numpy.uint8) for 16 bits";
    throw ArgumentTypeError(what + " has dtype " + py::str(array.dtype()).cast<std::string>() +
                            "; give a uint8 image (HxW grey or HxWx3 BGR): " + conversion);
  }
  const int channels = array.ndim() == 3 ? static_cast<int>(array.shape(2)) : 1;
  if ((array.ndim() != 2 && array.ndim() != 3) || (channels != 1 && channels != 3 && channels != 4)) {
    throw InputError(what + " has shape " + py::str(object.attr("shape")).cast<std::string>() +
                     "; give HxW (grey) or HxWx3 (BGR)");
  }
  // The size is checked before any copy: a broadcast array of a few bytes may stand for gigabytes.
  const py::ssize_t height = array.shape(0), width = array.shape(1);
  const py::ssize_t largest = std::numeric_limits<int>::max();
  const std::string problem = width > largest || height > largest
                                  ? "larger than any image"
                                  : FrameSizeProblem(cv::Size(static_cast<int>(width), static_cast<int>(height)));
  if (!problem.empty()) {
    throw InputError(what + " is " + std::to_string(width) + "x" + std::to_string(height) + ", " + problem +
                     "; give an image of a usable size");
  }
  ImageInput input;
  input.pixels = py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>::ensure(array);
  if (!input.pixels) throw py::error_already_set();
  input.image = cv::Mat(static_cast<int>(height), static_cast<int>(width), CV_8UC(channels),
                        const_cast<void*>(input.pixels.data()));
  return input;
}

py::array_t<std::uint8_t> ImageArray(const cv::Mat& image) {
  std::vector<py::ssize_t> shape = {image.rows, image.cols};
  if (image.channels() > 1) shape.push_back(image.channels());
  py::array_t<std::uint8_t> array(shape);
  const size_t row_bytes = static_cast<size_t>(image.cols) * image.elemSize();
  for (int r = 0; r < image.rows; ++r) std::memcpy(array.mutable_data(r), image.ptr(r), row_bytes);
  return array;
}

py::object MatrixArray(const cv::Matx33d& m, bool valid) {
  if (!valid) return py::none();
  py::array_t<double> array({3, 3});
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) array.mutable_at(r, c) = m(r, c);
  }
  return std::move(array);
}

py::object VectorArray(const cv::Vec3d& v, bool valid) {
  if (!valid) return py::none();
  py::array_t<double> array(3);
  for (int i = 0; i < 3; ++i) array.mutable_at(i) = v[i];
  return std::move(array);
}

}  // namespace vmap::python
