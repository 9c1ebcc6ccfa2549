#include "vmap/simulation/corridor_world.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/core/image_decode.h"
#include "vmap/core/option_ranges.h"
#include "vmap/simulation/procedural_texture.h"
#include "vmap/sources/frame_source.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

constexpr int kMaxTextures = 1000;
constexpr long kMaxTexturePixels = 64L * 1000 * 1000;
constexpr int kMaxTextureSide = 2048;

// The corridor's centre line as a closed or open list of vertices with arc lengths, and the miter direction at
// each vertex (the offset to the walls).
struct CentreLine {
  std::vector<cv::Point2d> points;  // a closed ring repeats its first point at the end
  std::vector<double> arc;
  std::vector<cv::Point2d> miter;  // unit left normal scaled by 1 / cos(half the turn)

  explicit CentreLine(const RoutePath& path) {
    points = path.points();
    if (path.closed()) points.push_back(points.front());
    arc.push_back(0.0);
    for (size_t i = 1; i < points.size(); ++i) arc.push_back(arc.back() + cv::norm(points[i] - points[i - 1]));
    const size_t n = points.size();
    std::vector<cv::Point2d> normals;
    for (size_t i = 0; i + 1 < n; ++i) {
      const cv::Point2d d = (points[i + 1] - points[i]) / cv::norm(points[i + 1] - points[i]);
      normals.emplace_back(-d.y, d.x);
    }
    for (size_t i = 0; i < n; ++i) {
      cv::Point2d before, after;
      if (i == 0) {
        before = path.closed() ? normals.back() : normals.front();
        after = normals.front();
      } else if (i + 1 == n) {
        before = normals.back();
        after = path.closed() ? normals.front() : normals.back();
      } else {
        before = normals[i - 1];
        after = normals[i];
      }
      cv::Point2d m = before + after;
      m /= cv::norm(m);
      miter.push_back(m / m.dot(after));
    }
  }

  double length() const { return arc.back(); }

  // The point `offset` metres left of the centre line at arc length s, between the miter points.
  cv::Vec3d At(double s, double offset, double z) const {
    s = std::clamp(s, 0.0, length());
    size_t i = std::upper_bound(arc.begin(), arc.end(), s) - arc.begin();
    i = std::clamp<size_t>(i, 1, points.size() - 1);
    const double span = arc[i] - arc[i - 1];
    const double f = span > 0.0 ? (s - arc[i - 1]) / span : 0.0;
    const cv::Point2d a = points[i - 1] + offset * miter[i - 1], b = points[i] + offset * miter[i];
    const cv::Point2d p = a + f * (b - a);
    return {p.x, p.y, z};
  }

  // The arc lengths of the vertices strictly between a and b.
  std::vector<double> Breaks(double a, double b) const {
    std::vector<double> breaks = {a};
    for (double s : arc) {
      if (s > a + 1e-9 && s < b - 1e-9) breaks.push_back(s);
    }
    breaks.push_back(b);
    return breaks;
  }
};

}  // namespace

void CorridorOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Section("Simulated corridor");
  visitor.Visit(
      OptionField{"width", "--corridor-width", "Corridor width between the walls (m)"}.Within(0.5, 50).Unit("m"),
      width);
  visitor.Visit(OptionField{"wall_height", "--wall-height", "Wall height (m)"}.Within(0.2, 50).Unit("m"), wall_height);
}

void CorridorOptions::Check() const { CheckFieldRanges(*this); }

std::vector<cv::Mat> ReadTextureFolder(const fs::path& directory, const std::string& field) {
  std::error_code ec;
  if (!fs::is_directory(directory, ec)) {
    throw OptionError(field, fmt::format("'{}' is not a folder; give a folder of images", directory.string()));
  }
  std::vector<std::string> names;
  for (const fs::directory_entry& entry : fs::directory_iterator(directory, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.empty() || name[0] == '.') continue;
    if (entry.is_directory(ec)) continue;
    names.push_back(name);
    if (static_cast<int>(names.size()) > kMaxTextures) {
      throw OptionError(field, fmt::format("'{}' holds more than {} files; give at most {} images", directory.string(),
                                           kMaxTextures, kMaxTextures));
    }
  }
  if (ec) throw OptionError(field, fmt::format("'{}' cannot be listed: {}", directory.string(), ec.message()));
  std::sort(names.begin(), names.end(), NaturalLess);
  std::vector<cv::Mat> images;
  for (const std::string& name : names) {
    const fs::path path = directory / name;
    std::string why_not;
    std::optional<ContainedFile> file = ContainedFile::OpenRegular(path, &why_not);
    if (!file)
      throw OptionError(
          field, fmt::format("'{}': '{}' {}; the folder must hold images only", directory.string(), name, why_not));
    cv::Mat image = DecodeImageFile(*file, cv::IMREAD_COLOR, kMaxTexturePixels, &why_not);
    if (image.empty()) {
      throw OptionError(field, fmt::format("'{}': '{}' {}; the folder must hold images only, of at most 64 megapixels",
                                           directory.string(), name, why_not));
    }
    if (image.cols < 16 || image.rows < 16) {
      throw OptionError(field, fmt::format("'{}': '{}' is {}x{}; a texture needs at least 16x16 pixels",
                                           directory.string(), name, image.cols, image.rows));
    }
    const int longer = std::max(image.cols, image.rows);
    if (longer > kMaxTextureSide) {
      const double scale = static_cast<double>(kMaxTextureSide) / longer;
      cv::resize(image, image, cv::Size(), scale, scale, cv::INTER_AREA);
    }
    images.push_back(image);
  }
  if (images.empty()) {
    throw OptionError(
        field, fmt::format("'{}' holds no images; give a folder of photographs (png, jpg, ...)", directory.string()));
  }
  return images;
}

std::vector<cv::Mat> ProceduralTextures(int count, unsigned seed) {
  cv::RNG rng(seed);
  std::vector<cv::Mat> textures;
  for (int i = 0; i < count; ++i) textures.push_back(RandomTexture(cv::Size(512, 512), rng));
  return textures;
}

int TexturesToCover(double length, const CorridorOptions& options) {
  // Square images: wall panels wall_height long, floor panels corridor width long; two end walls.
  const double shortest = std::min(options.wall_height, options.width);
  return std::min(kMaxTextures, 3 * static_cast<int>(std::ceil(length / shortest)) + 6);
}

CorridorWorld::CorridorWorld(const RoutePath& corridor, const CorridorOptions& options,
                             const std::vector<cv::Mat>& images)
    : options_(options) {
  if (images.empty()) throw InputError("a corridor world needs at least one texture image");
  std::vector<std::shared_ptr<const Texture>> textures;
  for (const cv::Mat& image : images) {
    textures.push_back(std::make_shared<Texture>(image));
    image_sizes_.push_back(image.size());
  }
  const CentreLine line(corridor);
  const double half = 0.5 * options.width, height = options.wall_height;
  int next_image = 0;
  auto add = [&](std::vector<cv::Vec3d> corners, int image, std::vector<cv::Point2d> texture_corners) {
    polygons_.push_back(TexturedQuad(corners, textures[image], texture_corners));
    image_of_polygon_.push_back(image);
  };
  // Deal the images to the three surfaces in turn until each reaches the corridor's end.
  double cursor[3] = {0.0, 0.0, 0.0};  // left wall, right wall, floor
  for (int surface = 0; cursor[0] < line.length() || cursor[1] < line.length() || cursor[2] < line.length();
       surface = (surface + 1) % 3) {
    if (cursor[surface] >= line.length()) continue;
    const int image = next_image;
    next_image = (next_image + 1) % static_cast<int>(images.size());
    const cv::Size size = image_sizes_[image];
    const double aspect = static_cast<double>(size.width) / size.height;
    const double start = cursor[surface];
    const double panel = aspect * (surface == 2 ? options.width : height);
    const double end = start + panel;
    cursor[surface] = end;
    const double w = size.width - 1, h = size.height - 1;
    auto u_of = [&](double s) { return (s - start) / panel * w; };
    const std::vector<double> breaks = line.Breaks(start, std::min(end, line.length()));
    for (size_t k = 0; k + 1 < breaks.size(); ++k) {
      const double a = breaks[k], b = breaks[k + 1];
      if (surface == 0) {  // the left wall, read left to right facing it: along the corridor
        add({line.At(a, half, height), line.At(b, half, height), line.At(b, half, 0), line.At(a, half, 0)}, image,
            {{u_of(a), 0}, {u_of(b), 0}, {u_of(b), h}, {u_of(a), h}});
      } else if (surface == 1) {  // the right wall, read against the corridor's direction
        add({line.At(b, -half, height), line.At(a, -half, height), line.At(a, -half, 0), line.At(b, -half, 0)}, image,
            {{w - u_of(b), 0}, {w - u_of(a), 0}, {w - u_of(a), h}, {w - u_of(b), h}});
      } else {
        add({line.At(a, half, 0), line.At(b, half, 0), line.At(b, -half, 0), line.At(a, -half, 0)}, image,
            {{u_of(a), 0}, {u_of(b), 0}, {u_of(b), h}, {u_of(a), h}});
      }
    }
  }
  if (!corridor.closed()) {
    // End walls across both ends, read from inside the corridor.
    const double last = line.length();
    for (int end = 0; end < 2; ++end) {
      const int image = next_image;
      next_image = (next_image + 1) % static_cast<int>(images.size());
      const double w = image_sizes_[image].width - 1, h = image_sizes_[image].height - 1;
      const double s = end == 0 ? 0.0 : last, left = end == 0 ? -half : half;
      add({line.At(s, left, height), line.At(s, -left, height), line.At(s, -left, 0), line.At(s, left, 0)}, image,
          {{0, 0}, {w, 0}, {w, h}, {0, h}});
    }
  }
}

CorridorWorld CorridorWorld::WithImages(const std::vector<cv::Mat>& images) const {
  if (images.size() != image_sizes_.size()) {
    throw InputError(fmt::format(
        "the repeat textures are {} images and the teach textures {}; give the same images in another season "
        "(the same names, so that they fall in the same places)",
        images.size(), image_sizes_.size()));
  }
  std::vector<std::shared_ptr<const Texture>> textures;
  for (size_t i = 0; i < images.size(); ++i) {
    cv::Mat fitted = images[i];
    if (fitted.size() != image_sizes_[i]) cv::resize(fitted, fitted, image_sizes_[i], 0, 0, cv::INTER_AREA);
    textures.push_back(std::make_shared<Texture>(fitted));
  }
  CorridorWorld world = *this;
  for (size_t p = 0; p < world.polygons_.size(); ++p) world.polygons_[p].texture = textures[image_of_polygon_[p]];
  return world;
}

}  // namespace vmap
