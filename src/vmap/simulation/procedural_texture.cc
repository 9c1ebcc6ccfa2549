#include "vmap/simulation/procedural_texture.h"

#include <opencv2/imgproc.hpp>

namespace vmap {

cv::Mat RandomTexture(cv::Size size, cv::RNG& rng) {
  cv::Mat texture(size, CV_8UC3, cv::Scalar::all(rng.uniform(60, 200)));
  const int shapes = size.area() / 400;
  for (int i = 0; i < shapes; ++i) {
    const cv::Point c(rng.uniform(0, size.width), rng.uniform(0, size.height));
    const cv::Scalar color(rng.uniform(0, 256), rng.uniform(0, 256), rng.uniform(0, 256));
    if (rng.uniform(0, 2) == 0) {
      cv::circle(texture, c, rng.uniform(3, 18), color, cv::FILLED, cv::LINE_AA);
    } else {
      const cv::Point d(rng.uniform(4, 30), rng.uniform(4, 30));
      cv::rectangle(texture, c, c + d, color, cv::FILLED);
    }
  }
  cv::GaussianBlur(texture, texture, cv::Size(3, 3), 0.8);
  return texture;
}

}  // namespace vmap
