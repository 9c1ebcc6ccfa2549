#pragma once
// The simulated world: a corridor along the route, its two walls and its floor covered with photographs (or
// procedural textures) placed along it in order, rendered with perspective by plane_renderer.h.
//
// The images of a texture folder are taken in natural order (img2 before img10) and dealt in turn to the left
// wall, the right wall and the floor, each laid along the corridor after the one before on its surface, at its
// own aspect ratio (a wall panel is wall_height high, a floor panel corridor_width wide), over again when the
// corridor is longer than they reach. Two folders of the same images in two seasons (the same names, so the
// same order) therefore put the same places at the same spots: the repeat world takes the teach world's panels
// and shows the other folder's images in them.

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/core/option_fields.h"
#include "vmap/simulation/plane_renderer.h"
#include "vmap/simulation/route_path.h"

namespace vmap {

struct CorridorOptions {
  double width = 3.0;        // metres between the walls
  double wall_height = 2.0;  // metres

  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

// The images of `directory`, the option `field` ("teach_textures"), in natural order. Every regular file whose
// name does not start with '.' must be an image OpenCV decodes; larger ones are scaled to 2048 pixels on their
// longer side. Throws an OptionError of `field` naming the file (so each front end names the option its way): a
// file that is not an image, a folder without images or with more than 1000, an image of more than 64 megapixels.
std::vector<cv::Mat> ReadTextureFolder(const std::filesystem::path& directory, const std::string& field);

// `count` procedural textures (procedural_texture.h) drawn from `seed`: for worlds without photographs.
std::vector<cv::Mat> ProceduralTextures(int count, unsigned seed);

// How many images a corridor of `length` metres takes before they repeat, at most: enough procedural textures.
int TexturesToCover(double length, const CorridorOptions& options);

class CorridorWorld {
 public:
  // The corridor along `corridor` (its centre line) with `images` placed as described above. Throws
  // InputError when `images` is empty.
  CorridorWorld(const RoutePath& corridor, const CorridorOptions& options, const std::vector<cv::Mat>& images);

  // The same panels showing `images` instead: image i of the new list in every panel image i held (the same
  // number of images is required; each is fitted to the size of the one it replaces). Throws InputError when
  // the counts differ.
  CorridorWorld WithImages(const std::vector<cv::Mat>& images) const;

  const std::vector<TexturedPolygon>& polygons() const { return polygons_; }
  const CorridorOptions& options() const { return options_; }

 private:
  CorridorWorld() = default;

  CorridorOptions options_;
  std::vector<TexturedPolygon> polygons_;
  std::vector<int> image_of_polygon_;  // the index in the image list each polygon shows
  std::vector<cv::Size> image_sizes_;
};

}  // namespace vmap
