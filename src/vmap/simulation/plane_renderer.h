#pragma once
// Renders a world of textured planar polygons through a pinhole camera: each polygon is a homography from its
// texture to the image (cv::warpPerspective into the polygon's bounding box, masked by the polygon clipped to
// the camera's near plane), drawn far to near so that the nearest wins (painter's order by depth). A texture
// minified on screen is read from its mip level, so that distant walls do not shimmer with aliasing.
// Measured at 640x480 in docs/drive.md (bench/drive_bench.py, its timing run).

#include <memory>
#include <vector>

#include <opencv2/core.hpp>

namespace vmap {

// An image and its mip levels (each half the size of the one before, down to 8 pixels).
class Texture {
 public:
  explicit Texture(cv::Mat image);  // 8-bit, 1 or 3 channels
  const cv::Mat& level(int index) const { return levels_[index]; }
  int num_levels() const { return static_cast<int>(levels_.size()); }
  cv::Size size() const { return levels_.front().size(); }

 private:
  std::vector<cv::Mat> levels_;
};

// A convex planar quadrilateral of the world showing a region of a texture: the region's corners (level-0
// texture pixels) are mapped to the quad's corners by a homography of the quad's plane, so that a rectangle
// shows its texture undistorted and a trapezoid (a floor tile along a curve) shows it stretched.
struct TexturedPolygon {
  std::vector<cv::Vec3d> corners;            // 4, convex, planar, in order around the quad (world, metres)
  std::vector<cv::Point2d> texture_corners;  // the texture pixel at each corner
  std::shared_ptr<const Texture> texture;
  cv::Matx43d texture_to_world;  // homogeneous: X ~ M (u, v, 1)
};

// The quad `corners` showing the texture's region `texture_corners` (corners in the same order).
TexturedPolygon TexturedQuad(const std::vector<cv::Vec3d>& corners, std::shared_ptr<const Texture> texture,
                             const std::vector<cv::Point2d>& texture_corners);
// The rectangle or parallelogram tl, tr, br, bl showing the whole texture (pixel centres at its corners).
TexturedPolygon TexturedQuad(const cv::Vec3d& tl, const cv::Vec3d& tr, const cv::Vec3d& br, const cv::Vec3d& bl,
                             std::shared_ptr<const Texture> texture);

// A pinhole camera: x_image ~ K (R X + t), world to camera (camera x right, y down, z forward).
struct PinholeView {
  cv::Matx33d K = cv::Matx33d::eye();
  cv::Size size;
  cv::Matx33d R = cv::Matx33d::eye();
  cv::Vec3d t;
};

struct RenderOptions {
  double near = 0.05;  // metres: what is nearer the camera plane is clipped away
  cv::Scalar background = cv::Scalar(40, 40, 40);
  bool mipmaps = true;  // read minified textures from their mip level (off: level 0 always)
  // How the tests' synthetic scenes (testing/synthetic_scene.h) were first drawn, which their expectations were
  // measured on: polygons with a corner nearer than `near` skipped rather than clipped, drawn in the order
  // given rather than far to near, their edges blended with black (texture border constant) and masked by
  // where the texture lands rather than by the polygon.
  bool legacy_synthetic = false;
};

// The image (8-bit BGR) of `polygons` seen by `view`.
cv::Mat RenderPolygons(const std::vector<TexturedPolygon>& polygons, const PinholeView& view,
                       const RenderOptions& options = {});

}  // namespace vmap
