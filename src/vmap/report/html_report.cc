#include "vmap/report/html_report.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "vmap/core/atomic_output.h"
#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/map/map_io.h"
#include "vmap/mapping/recorded_options.h"
#include "vmap/report/html_page.h"
#include "vmap/report/html_util.h"
#include "vmap/report/link_table.h"
#include "vmap/report/svg_plot.h"

namespace vmap {
namespace fs = std::filesystem;
using nlohmann::json;
using report::FormatExact;
using report::FormatFixed;
using report::HtmlEscape;
using report::kBlue;
using report::kGreen;
using report::kGrey;
using report::kOrange;
using report::kRed;
using report::PlotSeries;
using report::SvgPlot;
using report::UrlPath;

using report::Card;
using report::Displayable;
using report::DurationText;
using report::Numbered;
using report::OptionsSection;
using report::OptionText;
using report::PageEnd;
using report::PageStart;
using report::ParseOptions;
using report::Row;
using report::ScaledToWidth;
using report::SizeText;
using report::TimestampText;
using report::WriteJpeg;

namespace {

// The S(key, frame) plot: one line per key image over the frames compared with it, tau, the key images
// and the similarity of each link at the frame that became the next key image.
std::string SimilarityPlot(const VisualMap& map, double tau) {
  SvgPlot plot("similarity-plot", "frame index", "similarity S(key, frame)");
  plot.SetIntegerX(true);
  double y_high = 1.0;
  std::map<int, std::vector<const Evaluation*>> by_key;
  std::vector<int> key_order;
  for (const Evaluation& e : map.evaluations) {
    if (!by_key.count(e.key_frame)) key_order.push_back(e.key_frame);
    by_key[e.key_frame].push_back(&e);
    y_high = std::max(y_high, e.similarity);
  }
  for (const Link& l : map.links) y_high = std::max(y_high, l.similarity);
  plot.SetYRange(0.0, y_high);
  const int last_frame = std::max(map.num_frames - 1, 1);
  plot.SetXRange(0.0, last_frame);

  PlotSeries lines;
  lines.name = "S(key, frame)";
  lines.color = kBlue;
  lines.css_class = "evaluations";
  PlotSeries failed;
  failed.kind = PlotSeries::Kind::kCrosses;
  failed.name = "matching failed";
  failed.color = kRed;
  failed.css_class = "failed";
  failed.segments.emplace_back();
  for (int key_frame : key_order) {
    std::vector<const Evaluation*>& evaluations = by_key[key_frame];
    std::stable_sort(evaluations.begin(), evaluations.end(),
                     [](const Evaluation* a, const Evaluation* b) { return a->frame < b->frame; });
    std::vector<cv::Point2d> points;
    for (const Evaluation* e : evaluations) {
      points.emplace_back(e->frame, e->similarity);
      if (!e->matched) failed.segments[0].emplace_back(e->frame, e->similarity);
    }
    lines.segments.push_back(std::move(points));
    lines.segment_attributes.push_back("data-key-frame=\"" + std::to_string(key_frame) + "\"");
  }

  PlotSeries keys;
  keys.kind = PlotSeries::Kind::kVerticalRules;
  keys.name = "key image";
  keys.color = kGrey;
  keys.css_class = "key-images";
  keys.segments.emplace_back();
  for (const KeyImage& k : map.key_images) keys.segments[0].emplace_back(k.frame_index, 0.0);

  PlotSeries links, below_tau;
  links.kind = below_tau.kind = PlotSeries::Kind::kMarkers;
  links.name = "link S (next key image)";
  links.color = kGreen;
  links.css_class = "links";
  below_tau.name = "link below \u03c4";
  below_tau.color = kRed;
  below_tau.css_class = "below-tau-links";
  below_tau.marker_radius = 5.0;
  for (size_t i = 0; i < map.links.size(); ++i) {
    const Link& l = map.links[i];
    PlotSeries& target = l.below_tau ? below_tau : links;
    target.segments.push_back({cv::Point2d(map.key_images[l.to_key].frame_index, l.similarity)});
    target.segment_attributes.push_back("data-link=\"" + std::to_string(i) + "\"");
    target.point_titles.push_back(LinkTitle(map, static_cast<int>(i)) + ": S = " + FormatFixed(l.similarity, 3));
  }

  plot.Add(keys);
  if (!lines.segments.empty()) plot.Add(lines);
  if (!failed.segments[0].empty()) plot.Add(failed);
  PlotSeries rule;
  rule.kind = PlotSeries::Kind::kHorizontalRule;
  rule.name = "\u03c4 = " + FormatExact(tau);
  rule.color = kOrange;
  rule.css_class = "tau";
  rule.segments.push_back({cv::Point2d(0.0, tau)});
  rule.segment_attributes.push_back("data-tau=\"" + FormatExact(tau) + "\"");
  plot.Add(rule);
  if (!links.segments.empty()) plot.Add(links);
  if (!below_tau.segments.empty()) plot.Add(below_tau);
  return plot.Render();
}

std::string VerifiedPlot(const VisualMap& map) {
  SvgPlot plot("verified-plot", "frame index of the link's second key image", "verified matches");
  plot.SetSize(960, 260);
  plot.SetIntegerX(true);
  plot.SetIntegerY(true);
  plot.SetXRange(0.0, std::max(map.num_frames - 1, 1));
  PlotSeries line;
  line.name = "verified matches per link";
  line.color = kGreen;
  line.css_class = "verified";
  line.segments.emplace_back();
  PlotSeries tentative = line;
  tentative.name = "tentative matches";
  tentative.color = kGrey;
  tentative.css_class = "tentative";
  double high = 10.0;
  for (const Link& l : map.links) {
    const double x = map.key_images[l.to_key].frame_index;
    line.segments[0].emplace_back(x, l.num_verified);
    tentative.segments[0].emplace_back(x, l.num_tentative);
    high = std::max<double>(high, l.num_tentative);
  }
  plot.SetYRange(0.0, high);
  PlotSeries dots = line;
  dots.kind = PlotSeries::Kind::kMarkers;
  dots.name.clear();
  dots.marker_radius = 2.5;
  plot.Add(tentative);
  plot.Add(line);
  plot.Add(dots);
  return plot.Render();
}

// The key images in order as a short video: H.264 in MP4 where OpenCV's FFmpeg has an encoder for it, else
// VP9 in WebM; both play in current browsers. Without either, the page keeps only the step-through player.
class RouteVideo {
 public:
  RouteVideo(const fs::path& directory, const cv::Size& frame_size, double fps)
      // H.264 with 4:2:0 sampling needs even sides.
      : size_(std::max(2, frame_size.width & ~1), std::max(2, frame_size.height & ~1)) {
    const std::pair<const char*, int> candidates[] = {{"route.mp4", cv::VideoWriter::fourcc('a', 'v', 'c', '1')},
                                                      {"route.webm", cv::VideoWriter::fourcc('V', 'P', '9', '0')}};
    for (const auto& [name, fourcc] : candidates) {
      try {
        if (writer_.open((directory / name).string(), cv::CAP_FFMPEG, fourcc, fps, size_)) {
          file_name_ = name;
          path_ = directory / name;
          return;
        }
      } catch (const cv::Exception&) {
      }
      std::error_code ignored;
      fs::remove(directory / name, ignored);
    }
  }

  void Add(const cv::Mat& image, const std::string& label) {
    if (!writer_.isOpened()) return;
    cv::Mat frame;
    cv::resize(image, frame, size_, 0, 0, cv::INTER_AREA);
    const double scale = std::clamp(size_.width / 700.0, 0.35, 1.0);
    cv::putText(frame, label, cv::Point(7, size_.height - 9), cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar::all(0), 3,
                cv::LINE_AA);
    cv::putText(frame, label, cv::Point(7, size_.height - 9), cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar::all(255), 1,
                cv::LINE_AA);
    writer_.write(frame);
    ++frames_;
  }

  // Closes the file; false (and no file) when nothing usable was written.
  bool Finish() {
    if (!writer_.isOpened()) return false;
    writer_.release();
    std::error_code ec;
    if (frames_ > 0 && fs::file_size(path_, ec) > 0 && !ec) return true;
    fs::remove(path_, ec);
    return false;
  }

  const std::string& file_name() const { return file_name_; }
  const cv::Size& size() const { return size_; }

 private:
  cv::Size size_;
  cv::VideoWriter writer_;
  std::string file_name_;
  fs::path path_;
  int frames_ = 0;
};

}  // namespace

std::string LinkTitle(const VisualMap& map, int link_index) {
  const Link& l = map.links.at(link_index);
  return "key " + std::to_string(l.from_key) + " (frame " + std::to_string(map.key_images.at(l.from_key).frame_index) +
         ") -> key " + std::to_string(l.to_key) + " (frame " + std::to_string(map.key_images.at(l.to_key).frame_index) +
         ")";
}

cv::Mat DrawMapLink(const fs::path& map_directory, const VisualMap& map, int link_index,
                    const MatchFigureOptions& options) {
  if (link_index < 0 || link_index >= static_cast<int>(map.links.size())) {
    throw InputError("link " + std::to_string(link_index) + " does not exist: map '" + map_directory.string() +
                     "' has " + std::to_string(map.links.size()) + " links" +
                     (map.links.empty() ? "" : " (0 to " + std::to_string(map.links.size() - 1) + ")"));
  }
  const Link& link = map.links[link_index];
  MatchFigureOptions with_title = options;
  if (with_title.title.empty())
    with_title.title = "link " + std::to_string(link_index) + ": " + LinkTitle(map, link_index);
  return DrawMatchFigure(ReadKeyImage(map_directory, map.key_images[link.from_key]),
                         ReadKeyImage(map_directory, map.key_images[link.to_key]), link, with_title);
}

void MapReportOptions::Check() const {
  if (thumbnail_width < 32 || thumbnail_width > 4096) {
    throw OptionError("thumbnail_width",
                      "is " + std::to_string(thumbnail_width) + "; use 32 to 4096 pixels (default 320)");
  }
  if (figure_width < 64 || figure_width > 8192) {
    throw OptionError("figure_width", "is " + std::to_string(figure_width) + "; use 64 to 8192 pixels (default 960)");
  }
  if (jpeg_quality < 1 || jpeg_quality > 100) {
    throw OptionError("jpeg_quality", "is " + std::to_string(jpeg_quality) + "; use 1 to 100 (default 85)");
  }
  if (!(route_fps > 0.0 && route_fps <= 120.0)) {
    throw OptionError("route_fps", "is " + FormatExact(route_fps) +
                                       "; use more than 0 and at most 120 key images per second (default 3)");
  }
}

namespace {

// What WriteReportAssets wrote into report/, for the page to show.
struct ReportAssets {
  std::vector<cv::Size> thumbnail_sizes;  // per key image: report/keys/NNNNNN.jpg
  std::vector<cv::Size> figure_sizes;     // per link: report/links/NNNNNN.jpg
  std::string video_file;                 // the route video in report/; empty when none was written
  cv::Size video_size;
};

// A file in report/ as the page links it.
std::string AssetUrl(const std::string& relative) {
  return UrlPath(std::string(kReportAssetsDirectory) + "/" + relative);
}

// Writes the key-image thumbnails, the route video and the match figures into `directory` (report/ while
// it is being written).
ReportAssets WriteReportAssets(const fs::path& map_directory, const VisualMap& map, const MapReportOptions& options,
                               const fs::path& directory) {
  fs::create_directory(directory / "keys");  // not create_directories: see AtomicOutputDirectory::path()
  fs::create_directory(directory / "links");

  // Consecutive links share a key image: keep the last two decoded. (cv::Mat copies share the pixels, so a
  // returned image stays valid after it leaves the cache.)
  std::map<int, cv::Mat> cache;
  auto key_image = [&](int index) -> cv::Mat {
    auto it = cache.find(index);
    if (it != cache.end()) return it->second;
    while (cache.size() >= 2) cache.erase(cache.begin());
    return cache[index] = ReadKeyImage(map_directory, map.key_images[index]);
  };

  ReportAssets assets;
  std::unique_ptr<RouteVideo> video;
  for (size_t i = 0; i < map.key_images.size(); ++i) {
    const cv::Mat thumb = ScaledToWidth(key_image(static_cast<int>(i)), options.thumbnail_width);
    WriteJpeg(directory / "keys" / Numbered(static_cast<int>(i)), thumb, options.jpeg_quality);
    assets.thumbnail_sizes.push_back(thumb.size());
    if (i == 0 && options.route_video && map.key_images.size() > 1) {
      video = std::make_unique<RouteVideo>(directory, thumb.size(), options.route_fps);
    }
    if (video) {
      video->Add(thumb, "key " + std::to_string(i) + "  frame " + std::to_string(map.key_images[i].frame_index));
    }
  }
  if (video && video->Finish()) {
    assets.video_file = video->file_name();
    assets.video_size = video->size();
  }
  for (size_t i = 0; i < map.links.size(); ++i) {
    const Link& l = map.links[i];
    MatchFigureOptions figure_options;
    figure_options.max_width = options.figure_width;
    figure_options.title = "link " + std::to_string(i) + ": " + LinkTitle(map, static_cast<int>(i));
    const cv::Mat figure = DrawMatchFigure(key_image(l.from_key), key_image(l.to_key), l, figure_options);
    WriteJpeg(directory / "links" / Numbered(static_cast<int>(i)), figure, options.jpeg_quality);
    assets.figure_sizes.push_back(figure.size());
  }
  return assets;
}

std::string SummarySection(const VisualMap& map, const MapStatistics& stats, const json& options, double tau) {
  const int n = map.num_frames, m = static_cast<int>(map.key_images.size());
  std::ostringstream html;
  html << "<section id=\"summary\"><h2>Summary</h2>\n<div class=\"cards\">" << Card(std::to_string(n), "frames (n)")
       << Card(std::to_string(m), "key images (m)")
       << Card(n > 0 ? FormatFixed(100.0 * m / n, 1) + " %" : "n/a", "of the frames")
       << Card(FormatFixed(map.quality, 3), "quality Q") << Card(FormatFixed(stats.mean_similarity, 3), "mean S")
       << Card(std::to_string(stats.below_tau_links), "links below \u03c4") << "</div>\n<table class=\"summary\">\n";
  html << Row("Input", HtmlEscape(Displayable(map.input.path)))
       << Row("Format", HtmlEscape(SourceFormatName(map.input.format)))
       << Row("Frame size", HtmlEscape(SizeText(map.input.frame_size)) +
                                (map.input.native_size != map.input.frame_size && map.input.native_size.area() > 0
                                     ? " (native " + HtmlEscape(SizeText(map.input.native_size)) + ")"
                                     : ""))
       << (map.input.fps > 0 ? Row("Frame rate", FormatFixed(map.input.fps, 2) + " fps") : "")
       << Row("Matcher", HtmlEscape(OptionText(options, "matcher")))
       << Row("Verifier", HtmlEscape(OptionText(options, "verifier")))
       << Row("Threshold \u03c4", json(tau).dump())  // as map.json writes it
       << Row("Frames n", std::to_string(n) + (map.skipped_frames > 0 ? " (" + std::to_string(map.skipped_frames) +
                                                                            " unreadable frames skipped)"
                                                                      : ""))
       << Row("Key images m",
              std::to_string(m) + (n > 0 ? " (" + FormatFixed(100.0 * m / n, 1) + " % of the frames)" : ""))
       << Row("Links",
              std::to_string(map.links.size()) + ", " + std::to_string(stats.below_tau_links) + " below \u03c4")
       << Row("Verified matches per link", map.links.empty() ? std::string("no links")
                                                             : "min " + std::to_string(stats.min_verified) + ", max " +
                                                                   std::to_string(stats.max_verified) + ", mean " +
                                                                   FormatFixed(stats.mean_verified, 1))
       << Row("Mean similarity of links", FormatFixed(stats.mean_similarity, 3))
       << Row("Quality Q", FormatFixed(map.quality, 4))
       << Row("Build time", DurationText(map.seconds) +
                                (map.seconds > 0 && n > 0 ? " (" + FormatFixed(n / map.seconds, 1) + " frames/s)" : ""))
       << "</table>\n</section>\n";
  return html.str();
}

std::string SimilaritySection(const VisualMap& map, double tau) {
  std::string html = "<section id=\"similarity\"><h2>Similarity along the sequence</h2>\n";
  if (map.evaluations.empty()) {
    html +=
        "<p class=\"note\">This map records no per-frame similarities; only its links are shown. Rebuild it "
        "with a current vmap to see S for every frame.</p>\n";
  } else {
    html +=
        "<p class=\"note\">Each blue line follows S(key, frame) from one key image over the frames compared "
        "with it; a new key image is chosen where S drops below &tau;. A lower &tau; gives fewer key images "
        "with fewer shared matches.</p>\n";
  }
  html += SimilarityPlot(map, tau);
  if (!map.links.empty()) html += VerifiedPlot(map);
  return html + "</section>\n";
}

std::string KeyImagesSection(const VisualMap& map, const ReportAssets& assets) {
  const int m = static_cast<int>(map.key_images.size());
  std::ostringstream html;
  html << "<section id=\"key-images\"><h2>Key images (" << m << ")</h2>\n<div class=\"strip\">\n";
  for (int i = 0; i < m; ++i) {
    const KeyImage& k = map.key_images[i];
    const std::string timestamp = TimestampText(k.timestamp);
    const std::string label = "key " + std::to_string(i) + " | frame " + std::to_string(k.frame_index) +
                              (timestamp.empty() ? "" : " | t = " + timestamp);
    html << "<figure id=\"key-" << i << "\" title=\""
         << HtmlEscape(Displayable(k.source_name) + (k.reason.empty() ? "" : ": " + k.reason))
         << "\"><img loading=\"lazy\" decoding=\"async\" src=\"" << AssetUrl("keys/" + Numbered(i)) << "\" width=\""
         << assets.thumbnail_sizes[i].width << "\" height=\"" << assets.thumbnail_sizes[i].height
         << "\" alt=\"key image " << i << "\" data-label=\"" << HtmlEscape(label) << "\"><figcaption><b>#" << i
         << "</b> frame " << k.frame_index << (timestamp.empty() ? "" : " &middot; " + HtmlEscape(timestamp))
         << "</figcaption></figure>\n";
  }
  html << "</div>\n</section>\n";
  return html.str();
}

// The route video where one was written, and a player stepping through the thumbnails (report.js).
std::string RoutePreviewSection(const VisualMap& map, const ReportAssets& assets, double route_fps) {
  const int m = static_cast<int>(map.key_images.size());
  std::ostringstream html;
  html << "<section id=\"route-preview\"><h2>Route preview</h2>\n<div class=\"route\">\n";
  if (!assets.video_file.empty()) {
    html << "<figure><video id=\"route-video\" src=\"" << AssetUrl(assets.video_file) << "\" width=\""
         << assets.video_size.width << "\" height=\"" << assets.video_size.height << "\" poster=\""
         << AssetUrl("keys/" + Numbered(0))
         << "\" controls muted loop playsinline preload=\"metadata\"></video><figcaption class=\"note\">The key images "
            "in order, "
         << FormatExact(route_fps) << " per second (" << HtmlEscape(assets.video_file)
         << "): what a robot following this map expects to see.</figcaption></figure>\n";
  }
  if (m > 0) {
    html << "<figure><img id=\"route-image\" alt=\"key image\" width=\"" << assets.thumbnail_sizes[0].width
         << "\" height=\"" << assets.thumbnail_sizes[0].height << "\" src=\"" << AssetUrl("keys/" + Numbered(0))
         << "\"><figcaption><div class=\"controls\"><button id=\"route-play\" type=\"button\">Play</button>"
         << "<input id=\"route-slider\" type=\"range\" min=\"0\" max=\"" << m - 1 << "\" value=\"0\" "
         << "aria-label=\"key image\"></div><span id=\"route-label\" class=\"note\"></span></figcaption></figure>\n";
  }
  html << "</div>\n</section>\n";
  return html.str();
}

std::string MatchFiguresSection(const VisualMap& map, const ReportAssets& assets, const MapEvaluation* evaluation) {
  std::ostringstream html;
  html << "<section id=\"links\"><h2>Match figures (" << map.links.size() << " links)</h2>\n"
       << "<p class=\"note\">Consecutive key images side by side: <span class=\"legend-verified\">verified matches "
          "as green lines</span>, <span class=\"legend-rejected\">rejected tentative matches as blue points</span>. "
          "Links below &tau; (the frame right after the first key image already fell below &tau;, so it became the "
          "second key image) have a red frame.</p>\n"
       << "<div class=\"links\">\n";
  for (size_t i = 0; i < map.links.size(); ++i) {
    const Link& l = map.links[i];
    html << "<figure class=\"match-figure" << (l.below_tau ? " below-tau" : "") << "\" id=\"link-" << i
         << "\" data-from=\"" << l.from_key << "\" data-to=\"" << l.to_key << "\"><img loading=\"lazy\" "
         << "decoding=\"async\" src=\"" << AssetUrl("links/" + Numbered(static_cast<int>(i))) << "\" width=\""
         << assets.figure_sizes[i].width << "\" height=\"" << assets.figure_sizes[i].height << "\" alt=\"link " << i
         << "\"><figcaption>" << (l.below_tau ? "BELOW &tau; &middot; " : "") << "Link " << i << ": "
         << HtmlEscape(LinkTitle(map, static_cast<int>(i))) << " &middot; S = " << FormatFixed(l.similarity, 3)
         << " &middot; " << l.num_verified << " verified of " << l.num_tentative << " tentative"
         << (evaluation ? " &middot; " + HtmlEscape(EvaluationCaption(evaluation->links[i])) : "")
         << "</figcaption></figure>\n";
  }
  if (map.links.empty()) html << "<p class=\"note\">This map has a single key image: there are no links.</p>\n";
  html << "</div>\n</section>\n";
  return html.str();
}

// Every recorded option, folded away at the end of the page.
}  // namespace

void WriteMapReport(const fs::path& map_directory) { WriteMapReport(map_directory, MapReportOptions{}); }

void WriteMapReport(const fs::path& map_directory, const MapReportOptions& report_options) {
  report_options.Check();
  const RecordedMap read = ReadRecordedMap(map_directory);
  const VisualMap& map = read.map;
  // Every image path is checked before anything is written.
  for (const KeyImage& k : map.key_images) KeyImageFile(map_directory, k);
  const json options = ParseOptions(map.options_json);  // shown as recorded, whatever this vmap knows of them
  const MapStatistics stats = ComputeStatistics(map, read.options.builder.quality_mean);
  const std::optional<MapEvaluation> evaluation = ReadMatchingEvaluation(map_directory, map);

  // Inside a map that ReadMap has just recognised as vmap's: the old report/ is vmap's too.
  AtomicOutputDirectory assets_directory(map_directory / kReportAssetsDirectory, OutputPolicy::InsideVmapOutput());
  const ReportAssets assets = WriteReportAssets(map_directory, map, report_options, assets_directory.path());

  const std::string input_name =
      map.input.path.empty() ? map_directory.filename().string() : Displayable(map.input.path);
  std::string html = PageStart("vmap report: " + input_name, "Visual map of " + input_name,
                               std::to_string(map.key_images.size()) + " key images from " +
                                   std::to_string(map.num_frames) + " frames, Q = " + FormatFixed(map.quality, 3),
                               {{"summary", "Summary"},
                                {"similarity", "Similarity"},
                                {"key-images", "Key images"},
                                {"route-preview", "Route preview"},
                                {"link-table", "Links"},
                                {"links", "Match figures"},
                                {"options", "Options"}});
  html += SummarySection(map, stats, options, read.options.builder.key_images.tau);
  html += SimilaritySection(map, read.options.builder.key_images.tau);
  html += KeyImagesSection(map, assets);
  html += RoutePreviewSection(map, assets, report_options.route_fps);
  html += LinkTableHtml(map, evaluation ? &*evaluation : nullptr);
  html += MatchFiguresSection(map, assets, evaluation ? &*evaluation : nullptr);
  html += OptionsSection(options, "Every option used to build this map");
  html += PageEnd();

  assets_directory.Commit();
  WriteFileAtomically(map_directory / kReportFileName, html);
}

}  // namespace vmap
