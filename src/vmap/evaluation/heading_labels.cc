#include "vmap/evaluation/heading_labels.h"

#include <fstream>
#include <sstream>

#include "vmap/core/error.h"
#include "vmap/core/number_text.h"

namespace vmap {

std::vector<HeadingLabel> ReadHeadingLabels(const std::string& csv_path) {
  std::ifstream csv(csv_path);
  if (!csv) throw InputError("cannot read heading labels '" + csv_path + "'");
  std::vector<HeadingLabel> labels;
  std::string line;
  std::getline(csv, line);  // header: repeat_image,teach_image,dx_px
  for (int number = 2; std::getline(csv, line); ++number) {
    if (line.empty()) continue;
    std::stringstream row(line);
    HeadingLabel label;
    std::string dx;
    std::getline(row, label.repeat_image, ',');
    std::getline(row, label.teach_image, ',');
    std::getline(row, dx, ',');
    const std::optional<double> dx_px = ParseNumber(dx);
    if (!dx_px || label.repeat_image.empty() || label.teach_image.empty()) {
      throw InputError(csv_path + " line " + std::to_string(number) + " is not 'repeat_image,teach_image,dx_px'");
    }
    label.dx_px = *dx_px;
    labels.push_back(std::move(label));
  }
  return labels;
}

}  // namespace vmap
