#pragma once
// Hand-labelled headings between images of the same place (michigan_seasons' gt.csv): a header line, then
// "repeat_image,teach_image,dx_px" per pair, dx_px = x in the repeat image minus x in the teach image of the
// same scene point. What vmap's heading estimates are judged against (docs/seasons.md).

#include <string>
#include <vector>

namespace vmap {

struct HeadingLabel {
  std::string repeat_image, teach_image;  // paths relative to the CSV's folder
  double dx_px = 0.0;
};

// Throws InputError naming the file and line for a missing file or a malformed row.
std::vector<HeadingLabel> ReadHeadingLabels(const std::string& csv_path);

}  // namespace vmap
