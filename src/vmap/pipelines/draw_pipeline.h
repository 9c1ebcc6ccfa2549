#pragma once
// The draw pipeline: one link of a map drawn as its match figure (verified matches green, rejected blue) into a
// PNG or JPEG file, for papers and slides (`vmap draw MAP --link K -o FILE`).

#include <string>

#include <opencv2/core.hpp>

#include "vmap/core/option_fields.h"
#include "vmap/report/match_figure.h"

namespace vmap {

struct DrawPipelineOptions {
  std::string map;     // the map directory
  int link = 0;        // the link to draw: 0 joins the first two key images
  std::string output;  // the image file to write: .png, .jpg or .jpeg
  MatchFigureOptions figure;

  // The fields above, each once (positional map, "link", "output", the figure's "max_width" and "caption").
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

// Stages, in order:
//   1. the output's format from its extension, and the options;
//   2. the output, which may overwrite none of the map's files;
//   3. read the map;
//   4. draw the link's figure;
//   5. encode it and write it atomically.
// Returns the figure's size. Throws InputError (OptionError for an option) naming what is wrong and how to fix it.
cv::Size RunDrawPipeline(const DrawPipelineOptions& options);

}  // namespace vmap
