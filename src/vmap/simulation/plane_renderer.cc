#include "vmap/simulation/plane_renderer.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace vmap {

Texture::Texture(cv::Mat image) {
  CV_Assert(image.depth() == CV_8U && (image.channels() == 1 || image.channels() == 3) && !image.empty());
  if (image.channels() == 1) cv::cvtColor(image, image, cv::COLOR_GRAY2BGR);
  levels_.push_back(image);
  while (std::min(levels_.back().cols, levels_.back().rows) >= 16) {
    cv::Mat next;
    cv::pyrDown(levels_.back(), next);
    levels_.push_back(next);
  }
}

TexturedPolygon TexturedQuad(const std::vector<cv::Vec3d>& corners, std::shared_ptr<const Texture> texture,
                             const std::vector<cv::Point2d>& texture_corners) {
  CV_Assert(corners.size() == 4 && texture_corners.size() == 4 && texture);
  // An orthonormal frame of the quad's plane at its first corner.
  const cv::Vec3d e1 = cv::normalize(corners[1] - corners[0]);
  const cv::Vec3d normal = cv::normalize(e1.cross(corners[3] - corners[0]));
  const cv::Vec3d e2 = normal.cross(e1);
  std::vector<cv::Point2f> from, to;
  for (int i = 0; i < 4; ++i) {
    const cv::Vec3d d = corners[i] - corners[0];
    from.emplace_back(static_cast<float>(texture_corners[i].x), static_cast<float>(texture_corners[i].y));
    to.emplace_back(static_cast<float>(d.dot(e1)), static_cast<float>(d.dot(e2)));
  }
  const cv::Matx33d G(cv::getPerspectiveTransform(from, to));
  const cv::Matx43d frame(e1[0], e2[0], corners[0][0], e1[1], e2[1], corners[0][1], e1[2], e2[2], corners[0][2], 0, 0,
                          1);
  TexturedPolygon polygon;
  polygon.corners = corners;
  polygon.texture_corners = texture_corners;
  polygon.texture = std::move(texture);
  polygon.texture_to_world = frame * G;
  return polygon;
}

TexturedPolygon TexturedQuad(const cv::Vec3d& tl, const cv::Vec3d& tr, const cv::Vec3d& br, const cv::Vec3d& bl,
                             std::shared_ptr<const Texture> texture) {
  const double w = std::max(1, texture->size().width - 1), h = std::max(1, texture->size().height - 1);
  return TexturedQuad({tl, tr, br, bl}, std::move(texture), {{0, 0}, {w, 0}, {w, h}, {0, h}});
}

namespace {

// The polygon (camera coordinates) cut to z >= near (Sutherland-Hodgman against one plane).
std::vector<cv::Vec3d> ClipToNear(const std::vector<cv::Vec3d>& polygon, double near) {
  std::vector<cv::Vec3d> clipped;
  const size_t n = polygon.size();
  for (size_t i = 0; i < n; ++i) {
    const cv::Vec3d& a = polygon[i];
    const cv::Vec3d& b = polygon[(i + 1) % n];
    const bool a_in = a[2] >= near, b_in = b[2] >= near;
    if (a_in) clipped.push_back(a);
    if (a_in != b_in) clipped.push_back(a + (b - a) * ((near - a[2]) / (b[2] - a[2])));
  }
  return clipped;
}

struct Visible {
  const TexturedPolygon* polygon = nullptr;
  double depth = 0.0;  // mean depth of the clipped polygon's corners
  bool clipped = false;
  std::vector<cv::Point2d> image_corners;
  cv::Rect box;  // within the image
};

double PolygonArea(const std::vector<cv::Point2d>& points) {
  double twice = 0.0;
  for (size_t i = 0; i < points.size(); ++i) twice += points[i].cross(points[(i + 1) % points.size()]);
  return 0.5 * std::abs(twice);
}

// RenderOptions::legacy_synthetic: the whole frame warped through the homography of the projected corners (in
// float, as they were), edges blended with black, masked by where the texture lands: pixel for pixel the images
// the tests' expectations were measured on.
void DrawAsFirstDrawn(const TexturedPolygon& polygon, const PinholeView& view, cv::Mat& frame) {
  std::vector<cv::Point2f> source, projected;
  for (size_t i = 0; i < polygon.corners.size(); ++i) {
    const cv::Vec3d x = view.K * (view.R * polygon.corners[i] + view.t);
    projected.emplace_back(static_cast<float>(x[0] / x[2]), static_cast<float>(x[1] / x[2]));
    source.emplace_back(static_cast<float>(polygon.texture_corners[i].x),
                        static_cast<float>(polygon.texture_corners[i].y));
  }
  const cv::Mat& texture = polygon.texture->level(0);
  const cv::Mat H = cv::getPerspectiveTransform(source, projected);
  cv::Mat warped, mask;
  cv::warpPerspective(texture, warped, H, frame.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  cv::warpPerspective(cv::Mat(texture.size(), CV_8U, cv::Scalar(255)), mask, H, frame.size(), cv::INTER_NEAREST,
                      cv::BORDER_CONSTANT);
  warped.copyTo(frame, mask);
}

}  // namespace

cv::Mat RenderPolygons(const std::vector<TexturedPolygon>& polygons, const PinholeView& view,
                       const RenderOptions& options) {
  cv::Mat frame(view.size, CV_8UC3, options.background);
  const cv::Rect image_rect(0, 0, view.size.width, view.size.height);
  std::vector<Visible> visible;
  for (const TexturedPolygon& polygon : polygons) {
    std::vector<cv::Vec3d> camera;
    camera.reserve(polygon.corners.size());
    for (const cv::Vec3d& X : polygon.corners) camera.push_back(view.R * X + view.t);
    const bool all_in_front =
        std::all_of(camera.begin(), camera.end(), [&](const cv::Vec3d& c) { return c[2] >= options.near; });
    if (!all_in_front && options.legacy_synthetic) continue;
    if (!all_in_front) camera = ClipToNear(camera, options.near);
    if (camera.size() < 3) continue;
    Visible item;
    item.clipped = !all_in_front;
    item.polygon = &polygon;
    double min_x = 1e18, min_y = 1e18, max_x = -1e18, max_y = -1e18;
    for (const cv::Vec3d& c : camera) {
      const cv::Vec3d x = view.K * c;
      const cv::Point2d p(x[0] / x[2], x[1] / x[2]);
      item.image_corners.push_back(p);
      item.depth += c[2] / camera.size();
      min_x = std::min(min_x, p.x), max_x = std::max(max_x, p.x);
      min_y = std::min(min_y, p.y), max_y = std::max(max_y, p.y);
    }
    if (max_x < -1.0 || max_y < -1.0 || min_x > view.size.width || min_y > view.size.height) continue;
    const cv::Rect box(cv::Point(static_cast<int>(std::floor(std::max(min_x, -1.0))),
                                 static_cast<int>(std::floor(std::max(min_y, -1.0)))),
                       cv::Point(static_cast<int>(std::ceil(std::min(max_x, view.size.width + 1.0))) + 1,
                                 static_cast<int>(std::ceil(std::min(max_y, view.size.height + 1.0))) + 1));
    item.box = box & image_rect;
    if (item.box.empty()) continue;
    visible.push_back(std::move(item));
  }
  if (!options.legacy_synthetic) {
    std::stable_sort(visible.begin(), visible.end(),
                     [](const Visible& a, const Visible& b) { return a.depth > b.depth; });
  }

  cv::Mat warped, mask;
  for (const Visible& item : visible) {
    if (options.legacy_synthetic) {
      DrawAsFirstDrawn(*item.polygon, view, frame);
      continue;
    }
    const TexturedPolygon& polygon = *item.polygon;
    const Texture& texture = *polygon.texture;
    // The mip level whose pixels are about the size of the image's over this polygon.
    int level = 0;
    // (Quads the near plane cuts are magnified where they are cut: level 0.)
    if (options.mipmaps && !item.clipped) {
      const double texels = PolygonArea(polygon.texture_corners);
      const double pixels = PolygonArea(item.image_corners);
      if (pixels > 1.0 && texels > pixels) {
        level = std::min(texture.num_levels() - 1, static_cast<int>(std::floor(0.5 * std::log2(texels / pixels))));
      }
    }
    const double s = std::ldexp(1.0, level);
    // Level pixel (a, b) is level-0 pixel (s a, s b): pyrDown's kernel centres level pixel a on the pixel 2a below it
    // (not between 2a and 2a + 1, as a box filter's would).
    const cv::Matx33d to_level0(s, 0, 0, 0, s, 0, 0, 0, 1);
    cv::Matx34d camera;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) camera(r, c) = view.R(r, c);
      camera(r, 3) = view.t[r];
    }
    const cv::Matx33d plane = camera * polygon.texture_to_world;
    const cv::Matx33d shift(1, 0, -item.box.x, 0, 1, -item.box.y, 0, 0, 1);
    const cv::Matx33d H = shift * view.K * plane * to_level0;
    const cv::Mat& image = texture.level(level);
    cv::warpPerspective(image, warped, cv::Mat(H), item.box.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    mask.create(item.box.size(), CV_8U);
    mask.setTo(0);
    constexpr int kShift = 4;  // sub-pixel corners
    std::vector<cv::Point> corners;
    for (const cv::Point2d& p : item.image_corners) {
      corners.emplace_back(static_cast<int>(std::lround((p.x - item.box.x) * (1 << kShift))),
                           static_cast<int>(std::lround((p.y - item.box.y) * (1 << kShift))));
    }
    cv::fillConvexPoly(mask, corners, cv::Scalar(255), cv::LINE_8, kShift);
    warped.copyTo(frame(item.box), mask);
  }
  return frame;
}

}  // namespace vmap
