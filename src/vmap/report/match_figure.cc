#include "vmap/report/match_figure.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "vmap/core/error.h"

namespace vmap {

namespace {

cv::Mat ToBgr(const cv::Mat& image) {
  cv::Mat bgr;
  if (image.channels() == 1)
    cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  else if (image.channels() == 4)
    cv::cvtColor(image, bgr, cv::COLOR_BGRA2BGR);
  else
    bgr = image;
  if (bgr.depth() != CV_8U) bgr.convertTo(bgr, CV_8U);
  return bgr;
}

// Sub-pixel drawing: OpenCV takes fixed-point coordinates with `kShift` fractional bits.
constexpr int kShift = 4;
cv::Point Fixed(const cv::Point2d& p) {
  return {static_cast<int>(std::lround(p.x * (1 << kShift))), static_cast<int>(std::lround(p.y * (1 << kShift)))};
}

// Maps a pixel of an image scaled by `s` (pixel centres at integers on both sides) and shifted by `offset`.
cv::Point2d Scaled(const cv::Point2f& p, double s, const cv::Point2d& offset) {
  return {(p.x + 0.5) * s - 0.5 + offset.x, (p.y + 0.5) * s - 0.5 + offset.y};
}

}  // namespace

std::string MatchCaption(const Link& link) {
  const int drawn = static_cast<int>(link.correspondences.size());
  const int rejected = std::max(0, std::max(link.num_tentative, drawn) - link.num_verified);
  return fmt::format("S = {:.3f} | {} verified (green), {} rejected (blue) of {} tentative", link.similarity,
                     link.num_verified, rejected, link.num_tentative);
}

void MatchFigureOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit(OptionField{"max_width", "--width", "Scale the figure down to at most this width (0: full size)"}
                    .Within(64, 16384)
                    .Or(0)
                    .Meaning("0: full size"),
                max_width);
  visitor.Visit(OptionField{"title"}.NotRecorded(), title);
  visitor.Visit({"caption", "!--no-caption", "Leave out the caption band under the images"}, caption);
}

void MatchFigureOptions::Check() const {
  if (max_width != 0 && (max_width < 64 || max_width > 16384)) {
    throw OptionError("max_width",
                      "is " + std::to_string(max_width) + "; use 0 (the key images' own scale) or 64 to 16384 pixels");
  }
}

cv::Mat DrawMatchFigure(const cv::Mat& image0, const cv::Mat& image1, const Link& link,
                        const MatchFigureOptions& options) {
  options.Check();
  if (image0.empty() || image1.empty()) throw std::invalid_argument("DrawMatchFigure: empty key image");
  const cv::Mat bgr0 = ToBgr(image0), bgr1 = ToBgr(image1);

  // Both images at the taller one's height, then everything scaled down to fit max_width.
  const int height = std::max(bgr0.rows, bgr1.rows);
  double s0 = static_cast<double>(height) / bgr0.rows, s1 = static_cast<double>(height) / bgr1.rows;
  const int border = link.below_tau ? std::max(4, height / 60) : 0;
  const double gap_at_scale = std::max(4.0, height / 100.0);
  const double natural_width = bgr0.cols * s0 + bgr1.cols * s1 + gap_at_scale + 2 * border;
  const double fit = options.max_width > 0 ? std::min(1.0, options.max_width / natural_width) : 1.0;
  s0 *= fit;
  s1 *= fit;
  const int gap = std::max(2, static_cast<int>(std::lround(gap_at_scale * fit)));
  const int w0 = std::max(1, static_cast<int>(std::lround(bgr0.cols * s0)));
  const int w1 = std::max(1, static_cast<int>(std::lround(bgr1.cols * s1)));
  const int h = std::max(1, static_cast<int>(std::lround(height * fit)));
  const int b = link.below_tau ? std::max(3, static_cast<int>(std::lround(border * fit))) : 0;
  const int width = w0 + gap + w1 + 2 * b;

  // The caption's text scales with the figure so it stays readable in a thumbnail and on a slide; long
  // lines shrink to fit.
  std::vector<std::string> caption_lines;
  if (options.caption) {
    if (!options.title.empty()) caption_lines.push_back(options.title);
    caption_lines.push_back(MatchCaption(link));
    if (link.below_tau) caption_lines.front().insert(0, "BELOW TAU | ");
  }
  double font_scale = std::clamp(width / 1500.0, 0.38, 1.2);
  int thickness = font_scale > 0.8 ? 2 : 1;
  int baseline = 0;
  for (const std::string& line : caption_lines) {
    const int text_width = cv::getTextSize(line, cv::FONT_HERSHEY_SIMPLEX, font_scale, thickness, &baseline).width;
    if (text_width > width - 16) font_scale *= static_cast<double>(width - 16) / text_width;
  }
  thickness = font_scale > 0.8 ? 2 : 1;
  const cv::Size text_size = cv::getTextSize("Sg", cv::FONT_HERSHEY_SIMPLEX, font_scale, thickness, &baseline);
  const int line_height = text_size.height + baseline + static_cast<int>(8 * font_scale) + 4;
  const int caption_height = caption_lines.empty() ? 0 : line_height * static_cast<int>(caption_lines.size()) + 4;

  cv::Mat figure(h + 2 * b + caption_height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  if (b > 0) figure.setTo(kBelowTauColor);
  const cv::Point2d offset0(b, b), offset1(b + w0 + gap, b);
  cv::resize(bgr0, figure(cv::Rect(b, b, w0, h)), cv::Size(w0, h), 0, 0, cv::INTER_AREA);
  cv::resize(bgr1, figure(cv::Rect(b + w0 + gap, b, w1, h)), cv::Size(w1, h), 0, 0, cv::INTER_AREA);
  if (b > 0) figure(cv::Rect(b + w0, b, gap, h)).setTo(kBelowTauColor);

  const int verified = std::clamp(link.num_verified, 0, static_cast<int>(link.correspondences.size()));
  const double radius = std::max(1.5, std::min(width, h * 2) / 400.0);
  const int line_width = width > 1600 ? 2 : 1;
  // Rejected points first, so the verified lines stay on top.
  for (size_t i = verified; i < link.correspondences.size(); ++i) {
    const Correspondence& c = link.correspondences[i];
    cv::circle(figure, Fixed(Scaled(c.p0, s0, offset0)), static_cast<int>(std::lround(radius * (1 << kShift))),
               kRejectedColor, cv::FILLED, cv::LINE_AA, kShift);
    cv::circle(figure, Fixed(Scaled(c.p1, s1, offset1)), static_cast<int>(std::lround(radius * (1 << kShift))),
               kRejectedColor, cv::FILLED, cv::LINE_AA, kShift);
  }
  for (int i = 0; i < verified; ++i) {
    const Correspondence& c = link.correspondences[i];
    const cv::Point a = Fixed(Scaled(c.p0, s0, offset0)), z = Fixed(Scaled(c.p1, s1, offset1));
    cv::line(figure, a, z, kVerifiedColor, line_width, cv::LINE_AA, kShift);
    cv::circle(figure, a, static_cast<int>(std::lround(radius * 0.8 * (1 << kShift))), kVerifiedColor, cv::FILLED,
               cv::LINE_AA, kShift);
    cv::circle(figure, z, static_cast<int>(std::lround(radius * 0.8 * (1 << kShift))), kVerifiedColor, cv::FILLED,
               cv::LINE_AA, kShift);
  }

  if (!caption_lines.empty()) {
    const cv::Rect band(0, h + 2 * b, width, caption_height);
    figure(band).setTo(link.below_tau ? kBelowTauColor : cv::Scalar(48, 48, 48));
    int y = band.y + line_height - baseline - 4;
    for (const std::string& line : caption_lines) {
      cv::putText(figure, line, cv::Point(8, y), cv::FONT_HERSHEY_SIMPLEX, font_scale, cv::Scalar(255, 255, 255),
                  thickness, cv::LINE_AA);
      y += line_height;
    }
  }
  return figure;
}

}  // namespace vmap
