#include "vmap/report/html_report.h"

#include <cmath>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "vmap/core/atomic_output.h"
#include "vmap/core/error.h"
#include "vmap/core/numeric.h"
#include "vmap/core/option_ranges.h"
#include "vmap/core/output_file.h"
#include "vmap/map/map_io.h"
#include "vmap/mapping/recorded_options.h"
#include "vmap/report/html_page.h"
#include "vmap/report/html_util.h"
#include "vmap/report/link_table.h"
#include "vmap/report/map_plots.h"
#include "vmap/report/map_report_files.h"

namespace vmap {
namespace fs = std::filesystem;
using nlohmann::json;
using report::Card;
using report::Displayable;
using report::DurationText;
using report::FormatExact;
using report::FormatFixed;
using report::HtmlEscape;
using report::IsMapReportFile;
using report::MapReportFiles;
using report::MatchFigureFile;
using report::OptionsSection;
using report::OptionText;
using report::PageEnd;
using report::PageStart;
using report::ParseOptions;
using report::Row;
using report::SimilarityPlot;
using report::SizeText;
using report::ThumbnailFile;
using report::TimestampText;
using report::UrlPath;
using report::VerifiedPlot;
using report::WriteMapReportFiles;

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

void MapReportOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit(OptionField{"thumbnail_width", "--thumbnail-width", "Width of the key-image thumbnails in pixels"}
                    .Within(32, 4096)
                    .Unit("px"),
                thumbnail_width);
  visitor.Visit(
      OptionField{"figure_width", "--figure-width", "Width of the match figures in pixels"}.Within(64, 8192).Unit("px"),
      figure_width);
  visitor.Visit(OptionField{"jpeg_quality"}.Within(1, 100), jpeg_quality);
  visitor.Visit({"route_video", "!--no-video", "Skip report/route.mp4, the video of the key images in order"},
                route_video);
  visitor.Visit(OptionField{"route_fps"}.Within(0, 120).ExcludingMin().Meaning("key images per second"), route_fps);
}

void MapReportOptions::Check() const { CheckFieldRanges(*this); }

namespace {

// A file in report/ as the page links it.
std::string AssetUrl(const std::string& relative) {
  return UrlPath(std::string(kReportAssetsDirectory) + "/" + relative);
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

std::string KeyImagesSection(const VisualMap& map, const MapReportFiles& assets) {
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
         << "\"><img loading=\"lazy\" decoding=\"async\" src=\"" << AssetUrl(ThumbnailFile(i)) << "\" width=\""
         << assets.thumbnail_sizes[i].width << "\" height=\"" << assets.thumbnail_sizes[i].height
         << "\" alt=\"key image " << i << "\" data-label=\"" << HtmlEscape(label) << "\"><figcaption><b>#" << i
         << "</b> frame " << k.frame_index << (timestamp.empty() ? "" : " &middot; " + HtmlEscape(timestamp))
         << "</figcaption></figure>\n";
  }
  html << "</div>\n</section>\n";
  return html.str();
}

// The route video where one was written, and a player stepping through the thumbnails (report.js).
std::string RoutePreviewSection(const VisualMap& map, const MapReportFiles& assets, double route_fps) {
  const int m = static_cast<int>(map.key_images.size());
  std::ostringstream html;
  html << "<section id=\"route-preview\"><h2>Route preview</h2>\n<div class=\"route\">\n";
  if (!assets.video_file.empty()) {
    html << "<figure><video id=\"route-video\" src=\"" << AssetUrl(assets.video_file) << "\" width=\""
         << assets.video_size.width << "\" height=\"" << assets.video_size.height << "\" poster=\""
         << AssetUrl(ThumbnailFile(0))
         << "\" controls muted loop playsinline preload=\"metadata\"></video><figcaption class=\"note\">The key images "
            "in order, "
         << FormatExact(route_fps) << " per second (" << HtmlEscape(assets.video_file)
         << "): what a robot following this map expects to see.</figcaption></figure>\n";
  }
  if (m > 0) {
    html << "<figure><img id=\"route-image\" alt=\"key image\" width=\"" << assets.thumbnail_sizes[0].width
         << "\" height=\"" << assets.thumbnail_sizes[0].height << "\" src=\"" << AssetUrl(ThumbnailFile(0))
         << "\"><figcaption><div class=\"controls\"><button id=\"route-play\" type=\"button\">Play</button>"
         << "<input id=\"route-slider\" type=\"range\" min=\"0\" max=\"" << m - 1 << "\" value=\"0\" "
         << "aria-label=\"key image\"></div><span id=\"route-label\" class=\"note\"></span></figcaption></figure>\n";
  }
  html << "</div>\n</section>\n";
  return html.str();
}

std::string MatchFiguresSection(const VisualMap& map, const MapReportFiles& assets, const MapEvaluation* evaluation) {
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
         << "decoding=\"async\" src=\"" << AssetUrl(MatchFigureFile(static_cast<int>(i))) << "\" width=\""
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

// The page's sections, for its navigation: the experiences' where the map has any.
std::vector<std::pair<std::string, std::string>> Sections(const VisualMap& map) {
  std::vector<std::pair<std::string, std::string>> sections = {
      {"summary", "Summary"},       {"similarity", "Similarity"},
      {"key-images", "Key images"}, {"route-preview", "Route preview"},
      {"link-table", "Links"},      {"links", "Match figures"}};
  if (!map.experiences.empty()) sections.emplace_back("experiences", "Experiences");
  sections.emplace_back("options", "Options");
  return sections;
}

// Other runs of the route added to the map (map/experiences.h): which key images each gave a view, and how well the
// views matched their key images when they were chosen.
std::string ExperiencesSection(const VisualMap& map) {
  std::ostringstream html;
  html << "<section id=\"experiences\"><h2>Experiences (" << map.experiences.size() << ")</h2>\n"
       << "<p class=\"note\">Repeat runs added with <code>vmap build RUN --add-experience-to MAP</code>: a frame is "
          "compared with each key image and its views, and S is measured against the one that fits best.</p>\n"
       << "<table class=\"summary\"><thead><tr><th class=\"num\">experience</th><th>run</th>"
          "<th class=\"num\">views</th><th class=\"num\">median verified</th><th>key images without a view</th>"
          "</tr></thead><tbody>\n";
  for (const Experience& e : map.experiences) {
    std::vector<double> verified;
    std::vector<bool> has_view(map.key_images.size(), false);
    for (const ExperienceView& view : e.views) {
      verified.push_back(view.num_verified);
      has_view.at(view.key) = true;
    }
    const double median_verified = MedianOrNan(verified);
    std::vector<int> without;
    for (size_t k = 0; k < has_view.size(); ++k) {
      if (!has_view[k]) without.push_back(static_cast<int>(k));
    }
    html << "<tr><td class=\"num\">" << e.id << "</td><td>" << HtmlEscape(Displayable(e.source))
         << "</td><td class=\"num\">" << e.views.size() << " of " << map.key_images.size() << "</td><td class=\"num\">"
         << (std::isfinite(median_verified) ? FormatExact(median_verified) : "") << "</td><td>"
         << (without.empty() ? "none" : HtmlEscape(fmt::format("{}", fmt::join(without, ", ")))) << "</td></tr>\n";
  }
  html << "</tbody></table>\n</section>\n";
  return html.str();
}

}  // namespace

void WriteMapReport(const fs::path& map_directory) { WriteMapReport(map_directory, MapReportOptions{}); }

void WriteMapReport(const fs::path& map_directory, const MapReportOptions& report_options) {
  report_options.Check();
  // The map is read first: a map that does not exist is named as such, not as a page whose folder is missing.
  const RecordedMap read = ReadRecordedMap(map_directory);
  // report.html is checked before report/ is replaced: a page that may not be replaced (a link, read-only) refuses
  // the report before anything is written.
  CheckOutputFiles({{map_directory / kReportFileName, kReportFileName}}, {});
  const VisualMap& map = read.map;
  // Every image path is checked before anything is written.
  for (const KeyImage& k : map.key_images) KeyImageFile(map_directory, k);
  const json options = ParseOptions(map.options_json);  // shown as recorded, whatever this vmap knows of them
  const MapStatistics stats = ComputeStatistics(map, read.options.builder.quality_mean);
  const std::optional<MapEvaluation> evaluation = ReadMatchingEvaluation(map_directory, map);

  // Inside a map that ReadMap has just recognised as vmap's: the old report/ is vmap's too. What a user put there
  // besides the report's own files stays.
  OutputPolicy assets_policy = OutputPolicy::InsideVmapOutput();
  assets_policy.kind = "a map's report";
  assets_policy.is_own_entry = IsMapReportFile;
  AtomicOutputDirectory assets_directory(map_directory / kReportAssetsDirectory, assets_policy);
  const MapReportFiles assets = WriteMapReportFiles(map_directory, map, report_options, assets_directory.path());

  const std::string input_name =
      map.input.path.empty() ? map_directory.filename().string() : Displayable(map.input.path);
  std::string html = PageStart("vmap report: " + input_name, "Visual map of " + input_name,
                               std::to_string(map.key_images.size()) + " key images from " +
                                   std::to_string(map.num_frames) + " frames, Q = " + FormatFixed(map.quality, 3),
                               Sections(map));
  html += SummarySection(map, stats, options, read.options.builder.key_images.tau);
  html += SimilaritySection(map, read.options.builder.key_images.tau);
  html += KeyImagesSection(map, assets);
  html += RoutePreviewSection(map, assets, report_options.route_fps);
  html += LinkTableHtml(map, evaluation ? &*evaluation : nullptr);
  html += MatchFiguresSection(map, assets, evaluation ? &*evaluation : nullptr);
  if (!map.experiences.empty()) html += ExperiencesSection(map);
  html += OptionsSection(options, "Every option used to build this map");
  html += PageEnd();

  // The page is written before report/ goes in place, and put in place right after it: a page that cannot be
  // written (a full disk) leaves the old report whole, not new figures under the old page.
  PendingFile page(map_directory / kReportFileName, html);
  assets_directory.Commit();
  page.Commit();
}

}  // namespace vmap
