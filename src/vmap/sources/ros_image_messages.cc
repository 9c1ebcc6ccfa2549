#include "vmap/sources/ros_image_messages.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "vmap/core/error.h"
#include "vmap/core/image_header.h"
#include "vmap/sources/frame_source.h"
#include "vmap/sources/message_buffer.h"

namespace vmap {
namespace {

struct RawImage {
  uint32_t height = 0, width = 0, step = 0;
  std::string encoding;
  bool big_endian = false;
  const uint8_t* data = nullptr;
  size_t size = 0;
};

RawImage ReadRawImage(MessageBuffer& buffer) {
  RawImage image;
  image.height = buffer.U32();
  image.width = buffer.U32();
  image.encoding = buffer.String();
  image.big_endian = buffer.U8() != 0;
  image.step = buffer.U32();
  image.data = buffer.Bytes(&image.size);
  return image;
}

// OpenCV names a Bayer pattern by the second row's second and third pixels, ROS by the top-left 2x2 block:
// ROS's rggb is OpenCV's BG (the test mosaics a known image in each pattern and checks the round trip).
int BayerCode(const std::string& encoding) {
  if (encoding == "bayer_rggb8") return cv::COLOR_BayerBG2BGR;
  if (encoding == "bayer_bggr8") return cv::COLOR_BayerRG2BGR;
  if (encoding == "bayer_gbrg8") return cv::COLOR_BayerGR2BGR;
  if (encoding == "bayer_grbg8") return cv::COLOR_BayerGB2BGR;
  return -1;
}

// A depth camera's images (REP 118) have the encodings of no grey camera: a topic remapped to the depth image by
// mistake localized as if its depths were grey levels, and steered the robot.
constexpr const char* kGiveTheIntensityImage =
    "vmap localizes by the intensity image: give the camera's colour or grey topic (mono8, mono16, rgb8, bgr8, ...)";

void RefuseDepthImage(const std::string& encoding, const std::string& what) {
  if (encoding == "16UC1" || encoding == "32FC1") {
    throw InputError(what + " has image encoding '" + encoding + "', a depth image's (REP 118); " +
                     kGiveTheIntensityImage);
  }
}

// A CompressedImage's format names the image's encoding before a ';' ("16UC1; png compressed ",
// compressed_image_transport's); compressed_depth_image_transport writes "16UC1; compressedDepth" (a header before
// the PNG, or RVL) and older ones "compressedDepth" alone.
void RefuseCompressedDepthImage(const std::string& format, const std::string& what) {
  const size_t separator = format.find(';');
  std::string encoding = format.substr(0, separator);
  encoding.erase(0, encoding.find_first_not_of(' '));
  encoding.erase(encoding.find_last_not_of(' ') + 1);
  RefuseDepthImage(encoding, what);
  if (format.find("compressedDepth") != std::string::npos) {
    throw InputError(what + " has format '" + format + "', a compressed depth image's; " + kGiveTheIntensityImage);
  }
}

DecodedImage ConvertRawImage(const RawImage& raw, const std::string& what) {
  int type = -1, code = -1;
  const std::string& e = raw.encoding;
  RefuseDepthImage(e, what);
  if (e == "mono8" || e == "8UC1")
    type = CV_8UC1;
  else if (e == "mono16")
    type = CV_16UC1;
  else if (e == "bgr8" || e == "8UC3")
    type = CV_8UC3;
  else if (e == "rgb8")
    type = CV_8UC3, code = cv::COLOR_RGB2BGR;
  else if (e == "bgra8" || e == "8UC4")
    type = CV_8UC4, code = cv::COLOR_BGRA2BGR;
  else if (e == "rgba8")
    type = CV_8UC4, code = cv::COLOR_RGBA2BGR;
  else if (BayerCode(e) >= 0)
    type = CV_8UC1, code = BayerCode(e);
  if (type < 0) {
    throw InputError(what + " has image encoding '" + e +
                     "'; vmap reads mono8, mono16, rgb8, bgr8, rgba8, bgra8 and bayer_*8 (or a compressed topic)");
  }
  if (raw.width == 0 || raw.height == 0) {
    throw InputError(what + " is an empty image (" + std::to_string(raw.width) + "x" + std::to_string(raw.height) +
                     " " + e + ")");
  }
  const size_t row_bytes = size_t{raw.width} * CV_ELEM_SIZE(type);
  if (raw.width > INT32_MAX || raw.height > INT32_MAX || raw.step < row_bytes ||
      raw.size / std::max<size_t>(raw.step, 1) < raw.height) {
    throw InputError(what + " is malformed: " + std::to_string(raw.width) + "x" + std::to_string(raw.height) + " " + e +
                     " with step " + std::to_string(raw.step) + " needs more than its " + std::to_string(raw.size) +
                     " bytes of data");
  }
  // OpenCV takes rows only at whole elements (its "Step must be a multiple of esz1").
  if (raw.step % CV_ELEM_SIZE1(type) != 0) {
    throw InputError(what + " is malformed: " + e + " rows of step " + std::to_string(raw.step) +
                     " bytes, which is not a multiple of its " + std::to_string(CV_ELEM_SIZE1(type)) + "-byte values");
  }
  // A view of the message's bytes: converted below into images of their own.
  const cv::Mat view(static_cast<int>(raw.height), static_cast<int>(raw.width), type, const_cast<uint8_t*>(raw.data),
                     raw.step);
  DecodedImage image;
  if (type == CV_16UC1) {
    cv::Mat wide = view;
    if (raw.big_endian) {
      wide = view.clone();
      for (int y = 0; y < wide.rows; ++y) {
        for (uint16_t& v : cv::Mat_<uint16_t>(wide.row(y))) v = static_cast<uint16_t>(v << 8 | v >> 8);
      }
    }
    wide.convertTo(image.gray, CV_8U, 1.0 / 256.0);  // the high byte, as cv_bridge's mono16 -> mono8
  } else if (type == CV_8UC1 && code < 0) {
    image.gray = view.clone();
  } else {
    if (code < 0)
      image.color = view.clone();
    else
      cv::cvtColor(view, image.color, code);
    cv::cvtColor(image.color, image.gray, cv::COLOR_BGR2GRAY);
  }
  return image;
}

// The camera of a CameraInfo message, checked as a map's reader checks it: a calibration with fx NaN or a
// distortion of 1e9 is refused here, naming the message, rather than written into a map no command then reads.
Camera Checked(Camera camera, const std::string& what) {
  try {
    camera.Check();
  } catch (const InputError& error) {
    throw InputError(what + ": " + error.what() +
                     "; give the right intrinsics with --camera, or --camera none to build without them");
  }
  return camera;
}

}  // namespace

bool IsImageType(const std::string& type) {
  const std::string normalized = NormalizedTypeName(type);
  return normalized == kImageType || normalized == kCompressedImageType;
}

DecodedImage DecodeImageMessage(const uint8_t* data, size_t size, const std::string& type, MessageEncoding encoding,
                                const std::string& what) {
  MessageBuffer buffer(data, size, encoding, what);
  const double stamp = ReadHeaderStamp(buffer, encoding);
  DecodedImage image;
  if (NormalizedTypeName(type) == kImageType) {
    image = ConvertRawImage(ReadRawImage(buffer), what);
  } else {
    const std::string format = buffer.String();
    RefuseCompressedDepthImage(format, what);
    size_t bytes = 0;
    const uint8_t* compressed = buffer.Bytes(&bytes);
    const cv::Mat encoded(1, static_cast<int>(std::min<size_t>(bytes, INT32_MAX)), CV_8UC1,
                          const_cast<uint8_t*>(compressed));
    // A few bytes may announce 32000 x 32000 pixels: refused by the header, before the decoder allocates them.
    const std::optional<cv::Size> announced = ImageHeaderSize(compressed, bytes);
    if (announced && static_cast<long>(announced->width) * announced->height > kMaxFramePixels) {
      throw InputError(
          fmt::format("{} holds a compressed image whose header announces {}x{}, more than vmap's limit of "
                      "{} pixels per frame",
                      what, announced->width, announced->height, kMaxFramePixels));
    }
    // libjpeg decodes a JPEG cut short (a message truncated by its sender or a recording cut off) with its missing
    // rows grey, which would then be matched as if seen.
    if (const char* cut = CutShortImage(compressed, bytes)) throw InputError(what + " holds " + cut);
    cv::Mat decoded;
    try {
      if (bytes > 0) decoded = cv::imdecode(encoded, cv::IMREAD_UNCHANGED);
    } catch (const cv::Exception&) {
      decoded.release();
    }
    if (decoded.empty()) {
      throw InputError(what + " holds a compressed image (format '" + format +
                       "') that OpenCV cannot decode; vmap reads jpeg and png");
    }
    if (decoded.depth() == CV_16U) decoded.convertTo(decoded, CV_8U, 1.0 / 256.0);
    if (decoded.channels() == 1) {
      image.gray = decoded;
    } else {
      if (decoded.channels() == 4) cv::cvtColor(decoded, decoded, cv::COLOR_BGRA2BGR);
      image.color = decoded;
      cv::cvtColor(image.color, image.gray, cv::COLOR_BGR2GRAY);
    }
  }
  image.stamp = stamp;
  return image;
}

cv::Size ImageMessageSize(const uint8_t* data, size_t size, const std::string& type, MessageEncoding encoding,
                          const std::string& what) {
  if (NormalizedTypeName(type) == kImageType) {
    MessageBuffer buffer(data, size, encoding, what);
    ReadHeaderStamp(buffer, encoding);
    const uint32_t height = buffer.U32();
    const uint32_t width = buffer.U32();
    return {static_cast<int>(std::min<uint32_t>(width, INT32_MAX)),
            static_cast<int>(std::min<uint32_t>(height, INT32_MAX))};
  }
  return DecodeImageMessage(data, size, type, encoding, what).gray.size();
}

std::optional<Camera> DecodeCameraInfo(const uint8_t* data, size_t size, MessageEncoding encoding,
                                       const std::string& what) {
  MessageBuffer buffer(data, size, encoding, what);
  ReadHeaderStamp(buffer, encoding);
  const uint32_t height = buffer.U32();
  const uint32_t width = buffer.U32();
  const std::string model = buffer.String();
  std::vector<double> d = buffer.F64Array();
  double k[9];
  buffer.F64Fixed(k, 9);
  if (k[0] == 0.0 && k[4] == 0.0) return std::nullopt;  // an uncalibrated camera
  const cv::Size image_size(static_cast<int>(std::min<uint32_t>(width, INT32_MAX)),
                            static_cast<int>(std::min<uint32_t>(height, INT32_MAX)));
  if (model == "equidistant") {
    // ROS's equidistant is OpenCV's fisheye model: D = k1..k4 (camera_calibration's fisheye calibration).
    if (d.size() != 4) {
      throw InputError(what + ": equidistant distortion has " + std::to_string(d.size()) + " coefficients, not 4");
    }
    Camera camera = Camera::FromParams(CameraModel::kOpenCVFisheye, {k[0], k[4], k[2], k[5], d[0], d[1], d[2], d[3]},
                                       width == 0 || height == 0 ? cv::Size() : image_size);
    return Checked(std::move(camera), what);
  }
  if (model == "rational_polynomial") {
    if (d.size() > 8) {
      throw InputError(what + ": rational_polynomial distortion has " + std::to_string(d.size()) +
                       " coefficients, not 8");
    }
  } else if (model == "plumb_bob" || model.empty()) {
    if (d.size() > 5) {
      throw InputError(what + ": plumb_bob distortion has " + std::to_string(d.size()) + " coefficients, not 5");
    }
  } else {
    throw InputError(what + ": distortion model '" + model +
                     "' is none of plumb_bob, rational_polynomial and "
                     "equidistant; give --camera with rectified intrinsics, or --camera none");
  }
  while (!d.empty() && d.back() == 0.0) d.pop_back();
  if (d.size() > 0 && d.size() < 4) d.resize(4, 0.0);
  if (d.size() > 5) d.resize(8, 0.0);  // k4..k6 of the rational model
  Camera camera = Camera::Make(k[0], k[4], k[2], k[5], d, image_size);
  if (width == 0 || height == 0) camera.size = cv::Size();
  return Checked(std::move(camera), what);
}

}  // namespace vmap
