#pragma once
// The paper's match figure (Figure 4, Figures 7-18): two consecutive key images side by side, the verified
// matches as green lines between them and the rejected tentative matches as blue points, with a caption
// giving S and the counts. A link below tau (its second key image is the
// frame right after the first, which already fell below tau) gets a red border and a red caption.

#include <string>

#include <opencv2/core.hpp>

#include "vmap/core/option_fields.h"
#include "vmap/map/visual_map.h"

namespace vmap {

struct MatchFigureOptions {
  // Widest figure in pixels (images, gap and border); 0 keeps the key images' own scale.
  int max_width = 0;
  // First part of the caption, e.g. "key 3 (frame 120) -> key 4 (frame 161)"; S and the counts follow.
  // Hershey fonts draw ASCII only.
  std::string title;
  bool caption = true;

  // The flags of `vmap draw` (--width, --no-caption); the title is the caller's.
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

// Colours (BGR) used by the figure, shared with the report's legend and the tests.
inline const cv::Scalar kVerifiedColor(0, 200, 0);
inline const cv::Scalar kRejectedColor(255, 64, 0);
inline const cv::Scalar kBelowTauColor(0, 0, 220);

// `image0` is the link's first key image and `image1` its second (8-bit grey or BGR; their sizes may
// differ: both are scaled to the taller one's height). The correspondences are in each image's own
// pixel coordinates. Returns an 8-bit BGR image. Throws std::invalid_argument on an empty image, InputError on
// bad options.
cv::Mat DrawMatchFigure(const cv::Mat& image0, const cv::Mat& image1, const Link& link,
                        const MatchFigureOptions& options = {});

// The caption text of a link ("S = 0.412 | 123 verified (green), 175 rejected (blue) of 298 tentative").
std::string MatchCaption(const Link& link);

}  // namespace vmap
