#include "vmap/pipelines/draw_pipeline.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string_view>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "vmap/core/atomic_output.h"
#include "vmap/core/error.h"
#include "vmap/map/map_io.h"
#include "vmap/pipelines/output_policies.h"
#include "vmap/report/html_report.h"

namespace vmap {

void DrawPipelineOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit(OptionField{"map", "map", "Map directory written by `vmap build`"}.Positional(), map);
  visitor.Visit(
      OptionField{"link", "-l,--link", "Link index: 0 joins the first two key images"}.HideDefault().NotRecorded(),
      link);
  visitor.Visit(OptionField{"output", "-o,--output", "Image file to write (.png, .jpg)"}.HideDefault().NotRecorded(),
                output);
  visitor.VisitNested("", figure);
}

void DrawPipelineOptions::Check() const {
  if (link < 0) {
    throw OptionError("link",
                      std::to_string(link) + " is negative; give a link index (0 joins the first two key images)");
  }
  figure.Check();
}

cv::Size RunDrawPipeline(const DrawPipelineOptions& options) {
  // 1. The format, then the options.
  const std::filesystem::path output(options.output);
  std::string extension = output.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension != ".png" && extension != ".jpg" && extension != ".jpeg") {
    throw InputError("output '" + options.output + "' must end in .png, .jpg or .jpeg");
  }
  options.Check();

  // 2. The figure must not overwrite what it is drawn from (the map's files).
  CheckOutputs({{options.output, "output"}}, {MapInputs(options.map)});

  // 3-4. The map, and the link's figure.
  const VisualMap map = ReadMap(options.map);
  const cv::Mat figure = DrawMapLink(options.map, map, options.link, options.figure);

  // 5. Encoded, written atomically.
  std::vector<uchar> encoded;
  const std::vector<int> parameters = extension == ".png" ? std::vector<int>{cv::IMWRITE_PNG_COMPRESSION, 6}
                                                          : std::vector<int>{cv::IMWRITE_JPEG_QUALITY, 92};
  if (!cv::imencode(extension, figure, encoded, parameters)) {
    throw InputError("cannot encode the figure as '" + extension + "'");
  }
  WriteFileAtomically(output, std::string_view(reinterpret_cast<const char*>(encoded.data()), encoded.size()));
  return figure.size();
}

}  // namespace vmap
