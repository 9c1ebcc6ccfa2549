#include "vmap/report/localization_report.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "vmap/core/atomic_output.h"
#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/core/option_ranges.h"
#include "vmap/map/map_io.h"
#include "vmap/report/belief_plot.h"
#include "vmap/report/html_page.h"
#include "vmap/report/html_report.h"
#include "vmap/report/html_util.h"
#include "vmap/report/localized_frame_figure.h"
#include "vmap/report/svg_plot.h"

namespace vmap {
namespace fs = std::filesystem;
using report::ComparedImage;
using report::Displayable;
using report::FormatFixed;
using report::HtmlEscape;
using report::kBlue;
using report::kGreen;
using report::kOrange;
using report::kRed;
using report::PlotSeries;
using report::ReadComparedImage;
using report::SvgPlot;
using report::UrlPath;

namespace {

// The frames to show: the first frame of every lost streak (at most a quarter of the pairs), the first
// relocalized frame, and the rest spread evenly over the run.
std::vector<int> ChooseFrames(const std::vector<LocalizationResult>& frames, int count) {
  std::set<int> chosen;
  const int n = static_cast<int>(frames.size());
  if (n == 0 || count <= 0) return {};
  for (int i = 0; i < n && static_cast<int>(chosen.size()) < std::max(1, count / 4); ++i) {
    const bool starts_streak =
        frames[i].status == LocalizationStatus::kLost && (i == 0 || frames[i - 1].status != LocalizationStatus::kLost);
    if (starts_streak) chosen.insert(i);
  }
  for (int i = 0; i < n; ++i) {
    if (frames[i].status == LocalizationStatus::kRelocalized) {
      chosen.insert(i);
      break;
    }
  }
  const int wanted = std::min(count, n);
  const int remaining = wanted - static_cast<int>(chosen.size());
  for (int j = 0; j < remaining; ++j) {
    chosen.insert(remaining > 1 ? static_cast<int>(std::lround(static_cast<double>(j) * (n - 1) / (remaining - 1)))
                                : n / 2);
  }
  // Spread picks that fell on frames already chosen go to the first frames not shown yet.
  for (int i = 0; i < n && static_cast<int>(chosen.size()) < wanted; ++i) chosen.insert(i);
  return {chosen.begin(), chosen.end()};
}

std::string KeyPlot(const LocalizationRun& run, int num_keys) {
  SvgPlot plot("key-plot", "frame index", "key image");
  plot.SetIntegerX(true);
  plot.SetIntegerY(true);
  plot.SetYRange(-1.0, std::max(1, num_keys - 1));
  PlotSeries line, tracking, relocalized, uncertain, lost;
  line.name = "";
  line.color = "#9ab7d3";
  line.css_class = "key-line";
  tracking.kind = relocalized.kind = uncertain.kind = PlotSeries::Kind::kMarkers;
  lost.kind = PlotSeries::Kind::kCrosses;
  tracking.name = "tracking";
  tracking.color = kBlue;
  tracking.css_class = "tracking";
  tracking.marker_radius = 2.0;
  relocalized.name = "relocalized";
  relocalized.color = kOrange;
  relocalized.css_class = "relocalized";
  uncertain.name = "uncertain (the best guess; not to steer by)";
  uncertain.color = "#b0b0b0";
  uncertain.css_class = "uncertain";
  uncertain.marker_radius = 2.0;
  lost.name = "lost (at the last estimate; -1: none)";
  lost.color = kRed;
  lost.css_class = "lost";
  tracking.segments.emplace_back();
  relocalized.segments.emplace_back();
  uncertain.segments.emplace_back();
  lost.segments.emplace_back();
  std::vector<cv::Point2d> segment;
  for (const LocalizationResult& r : run.frames) {
    const cv::Point2d p(r.frame_index, r.key);
    switch (r.status) {
      case LocalizationStatus::kTracking:
        tracking.segments[0].push_back(p);
        break;
      case LocalizationStatus::kRelocalized:
        relocalized.segments[0].push_back(p);
        break;
      case LocalizationStatus::kLost:
        lost.segments[0].push_back(p);
        break;
      case LocalizationStatus::kUncertain:
        uncertain.segments[0].push_back(p);
        break;
    }
    if (r.status == LocalizationStatus::kLost) {
      if (!segment.empty()) line.segments.push_back(std::move(segment));
      segment.clear();
    } else {
      segment.push_back(p);
    }
  }
  if (!segment.empty()) line.segments.push_back(std::move(segment));
  plot.Add(std::move(line));
  plot.Add(std::move(tracking));
  plot.Add(std::move(relocalized));
  plot.Add(std::move(uncertain));
  plot.Add(std::move(lost));
  return plot.Render();
}

std::string SimilarityPlot(const LocalizationRun& run) {
  SvgPlot plot("localization-similarity-plot", "frame index", "similarity S");
  plot.SetIntegerX(true);
  plot.SetYRange(0.0, 1.0);
  PlotSeries to_key, to_next, lost;
  to_key.name = "S(frame, key)";
  to_key.color = kBlue;
  to_key.css_class = "to-key";
  to_next.name = "S(frame, next key)";
  to_next.color = kGreen;
  to_next.css_class = "to-next";
  lost.kind = PlotSeries::Kind::kCrosses;
  lost.name = "lost";
  lost.color = kRed;
  lost.css_class = "lost";
  lost.segments.emplace_back();
  std::vector<cv::Point2d> a, b;
  for (const LocalizationResult& r : run.frames) {
    if (r.status == LocalizationStatus::kLost) {
      lost.segments[0].emplace_back(r.frame_index, 0.0);
      if (!a.empty()) to_key.segments.push_back(std::move(a));
      if (!b.empty()) to_next.segments.push_back(std::move(b));
      a.clear();
      b.clear();
      continue;
    }
    a.emplace_back(r.frame_index, r.to_key.similarity);
    if (r.next_key >= 0) b.emplace_back(r.frame_index, r.to_next.similarity);
  }
  if (!a.empty()) to_key.segments.push_back(std::move(a));
  if (!b.empty()) to_next.segments.push_back(std::move(b));
  plot.Add(std::move(to_key));
  plot.Add(std::move(to_next));
  plot.Add(std::move(lost));
  return plot.Render();
}

}  // namespace

void LocalizationReportOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit(OptionField{"pairs"}.Within(0, 200), pairs);
  visitor.Visit(OptionField{"pair_width"}.Within(64, 8192).Unit("px"), pair_width);
  visitor.Visit(OptionField{"jpeg_quality"}.Within(1, 100), jpeg_quality);
}

void LocalizationReportOptions::Check() const { CheckFieldRanges(*this); }

namespace {

// The whole folder is replaced at once, and only when it is empty or an older report of a run.
OutputPolicy ReportPolicy(const fs::path& map_directory, const std::string& query, const fs::path& run_file = {}) {
  OutputPolicy policy;
  policy.why_not_ours = WhyNotALocalizationReport;
  policy.kind = "a vmap localization report";
  policy.inputs = {map_directory};
  // A run that names no query (a run JSON without query.path) has none to keep apart: "" would be the working folder.
  if (!query.empty()) policy.inputs.push_back(query);
  if (!run_file.empty()) policy.inputs.push_back(run_file);  // `vmap report RUN.json -o DIR`: DIR may not hold it
  return policy;
}

}  // namespace

void CheckLocalizationReportDirectory(const fs::path& directory, const fs::path& map_directory,
                                      const std::string& query) {
  CheckOutputDirectory(directory, ReportPolicy(map_directory, query));
}

bool QueryCanBeReadAgain(const LocalizationRunInfo& info) {
  if (IsLiveInput(info.query)) return false;
  std::error_code ec;
  const fs::file_status status = fs::status(info.query, ec);
  if (fs::is_directory(status)) return true;
  // A regular file read as a folder of images is one image, which OpenFrameSource opens as such only when
  // asked to detect the format; a FIFO or a device gives its frames once.
  return fs::is_regular_file(status) && info.query_format != SourceFormat::kImageFolder;
}

void WriteLocalizationReport(const LocalizationRun& run, const VisualMap& map, const fs::path& map_directory,
                             const fs::path& directory, const LocalizationReportOptions& options,
                             const RecordedFrames& recorded) {
  PrepareLocalizationReport(run, map, map_directory, directory, options, recorded)->Commit();
}

std::unique_ptr<AtomicOutputDirectory> PrepareLocalizationReport(const LocalizationRun& run, const VisualMap& map,
                                                                 const fs::path& map_directory,
                                                                 const fs::path& directory,
                                                                 const LocalizationReportOptions& options,
                                                                 const RecordedFrames& recorded) {
  options.Check();
  for (const KeyImage& k : map.key_images) KeyImageFile(map_directory, k);
  auto prepared = std::make_unique<AtomicOutputDirectory>(directory, ReportPolicy(map_directory, run.info.query));
  AtomicOutputDirectory& output = *prepared;
  const fs::path assets = output.path() / kReportAssetsDirectory;
  fs::create_directory(assets);  // not create_directories: see AtomicOutputDirectory::path()
  fs::create_directory(assets / "frames");

  struct WrittenPair {
    size_t index;  // into run.frames
    cv::Size size;
    std::string key_label, next_label;  // ComparedImage::label
  };
  std::vector<WrittenPair> written;
  const auto write_pair = [&](size_t index, const cv::Mat& frame_image) {
    const LocalizationResult& r = run.frames[index];
    const bool known_key = r.key >= 0 && r.key < static_cast<int>(map.key_images.size());
    const bool known_next = r.next_key >= 0 && r.next_key < static_cast<int>(map.key_images.size());
    const ComparedImage key = known_key ? ReadComparedImage(map_directory, map, r.key, r.to_key) : ComparedImage{};
    const ComparedImage next_key =
        known_next ? ReadComparedImage(map_directory, map, r.next_key, r.to_next) : ComparedImage{};
    const cv::Mat pair = report::DrawLocalizedFrame(frame_image, key, next_key, r, options.pair_width);
    report::WriteJpeg(assets / "frames" / report::Numbered(r.frame_index), pair, options.jpeg_quality);
    written.push_back({index, pair.size(), key.label, next_key.label});
  };
  const bool read_again = recorded.empty() && QueryCanBeReadAgain(run.info);
  // The frames the run kept, in frame order: the last options.pairs of them.
  std::vector<size_t> kept;
  for (size_t i = 0; i < run.frames.size(); ++i) {
    const auto found = recorded.find(run.frames[i].frame_index);
    if (found != recorded.end() && !found->second.empty()) kept.push_back(i);
  }
  const size_t skip = kept.size() > static_cast<size_t>(options.pairs) ? kept.size() - options.pairs : 0;
  for (size_t k = skip; k < kept.size(); ++k) write_pair(kept[k], recorded.at(run.frames[kept[k]].frame_index));
  // Else the chosen frames, read again from the query (streamed: only the chosen ones are kept).
  const std::vector<int> chosen = read_again ? ChooseFrames(run.frames, options.pairs) : std::vector<int>();
  if (!chosen.empty()) {
    FrameSourceOptions source_options = run.info.source;
    source_options.format = run.info.query_format;
    source_options.allow_single_image = true;
    const std::unique_ptr<FrameSource> source = OpenFrameSource(run.info.query, source_options);
    size_t next = 0;
    while (next < chosen.size()) {
      std::optional<Frame> frame = source->Next();
      if (!frame) break;
      while (next < chosen.size() && run.frames[chosen[next]].frame_index < frame->index) ++next;
      if (next == chosen.size() || run.frames[chosen[next]].frame_index != frame->index) continue;
      write_pair(static_cast<size_t>(chosen[next]), ColorImage(*frame));
      ++next;
    }
  }

  const LocalizationSummary& s = run.summary;
  const double n = s.frames > 0 ? static_cast<double>(s.frames) : 1.0;
  const std::string assets_url = std::string(kReportAssetsDirectory) + "/";
  std::ostringstream html;
  // Paths as the run recorded them, in bytes: a name that is not UTF-8 is shown percent-encoded, as the map's page
  // shows it, not as bytes the UTF-8 page would turn into replacement characters.
  const std::string query_name = Displayable(run.info.query);
  const std::string map_name = Displayable(run.info.map_directory);
  html << report::PageStart(
      "vmap localization: " + query_name, "Localization of " + query_name,
      "against the map " + map_name + " (" + std::to_string(map.key_images.size()) + " key images)",
      {{"summary", "Summary"},
       {"keys", "Key image over time"},
       {"similarity", "Similarity"},
       {"frames", "Frames and key images"}});
  html << "<section id=\"summary\"><h2>Summary</h2>\n<div class=\"cards\">"
       << report::Card(std::to_string(s.frames), "frames")
       << report::Card(FormatFixed(100.0 * s.tracking / n, 1) + " %", "tracking")
       << report::Card(FormatFixed(100.0 * s.relocalized / n, 1) + " %", "relocalized")
       << report::Card(FormatFixed(100.0 * s.uncertain / n, 1) + " %", "uncertain")
       << report::Card(FormatFixed(100.0 * s.lost / n, 1) + " %", "lost")
       << report::Card(FormatFixed(s.frames_per_second, 1), "frames/s") << "</div>\n<table class=\"summary\">\n"
       << report::Row("Map", HtmlEscape(map_name))
       << report::Row("Query", HtmlEscape(query_name) + " (" + HtmlEscape(SourceFormatName(run.info.query_format)) +
                                   ", " + HtmlEscape(report::SizeText(run.info.frame_size)) + ")")
       << report::Row("Matcher", HtmlEscape(run.info.matcher))
       << report::Row("Relocalization ranking", HtmlEscape(run.info.ranking))
       << report::Row("Frames", fmt::format("{}: {} tracking, {} relocalized, {} uncertain, {} lost", s.frames,
                                            s.tracking, s.relocalized, s.uncertain, s.lost))
       << report::Row("Time", report::DurationText(s.seconds) + " (" + FormatFixed(s.frames_per_second, 1) +
                                  " frames/s; " + FormatFixed(1000.0 * s.mean_localize_seconds, 1) +
                                  " ms localizing and " + FormatFixed(1000.0 * s.mean_extract_seconds, 1) +
                                  " ms extracting per frame)")
       << report::Row("Key images", FormatFixed(run.info.key_image_seconds, 2) +
                                        " s to load (cache: " + HtmlEscape(run.info.cache) + ")")
       << "</table>\n</section>\n";
  html << "<section id=\"keys\"><h2>Key image over time</h2>\n<p class=\"note\">The key image each frame was "
          "localized at (the last one reached on the route): tracking in blue, relocalization in orange, "
          "uncertain frames (the best guess) in grey, lost frames as red crosses.</p>\n"
       << KeyPlot(run, static_cast<int>(map.key_images.size())) << "</section>\n";
  if (const std::string belief = report::BeliefPlot(run, static_cast<int>(map.key_images.size())); !belief.empty()) {
    html << "<section id=\"belief\"><h2>The belief over the route</h2>\n<p class=\"note\">Where the localizer "
            "believed each frame was along the route (each key image holding at least 1 % of the belief, darker "
            "where it held more), and the key image the frame was placed at (orange). A frame whose key image the "
            "belief does not hold is uncertain; a band that moves on while frames are lost is the belief carrying "
            "the estimate along the route.</p>\n"
         << belief << "</section>\n";
  }
  html << "<section id=\"similarity\"><h2>Similarity</h2>\n<p class=\"note\">S of each frame against its key image "
          "and against the next one; the estimate moves on when the next key image becomes the better match.</p>\n"
       << SimilarityPlot(run) << "</section>\n";
  html << "<section id=\"frames\"><h2>Frames and key images</h2>\n<p class=\"note\">A few frames of the query beside "
          "the key image they were localized at and the next key image, or the view of an experience where that fit "
          "best (lost frames in a red frame).</p>\n"
       << "<div class=\"links\">\n";
  for (const auto& [index, size, key_label, next_label] : written) {
    const LocalizationResult& r = run.frames[index];
    html << "<figure class=\"match-figure" << (r.status == LocalizationStatus::kLost ? " lost" : "") << "\" id=\"frame-"
         << r.frame_index << "\"><img loading=\"lazy\" decoding=\"async\" src=\""
         << UrlPath(assets_url + "frames/" + report::Numbered(r.frame_index)) << "\" width=\"" << size.width
         << "\" height=\"" << size.height << "\" alt=\"frame " << r.frame_index << "\"><figcaption>Frame "
         << r.frame_index << " (" << HtmlEscape(Displayable(r.source_name)) << "): " << LocalizationStatusName(r.status)
         << (r.key >= 0
                 ? fmt::format(" &middot; key {}{} (S = {})", r.key, key_label, FormatFixed(r.to_key.similarity, 3))
                 : "")
         << (r.next_key >= 0 ? fmt::format(" &middot; next {}{} (S = {})", r.next_key, next_label,
                                           FormatFixed(r.to_next.similarity, 3))
                             : "")
         << "</figcaption></figure>\n";
  }
  if (written.empty() && recorded.empty() && !QueryCanBeReadAgain(run.info) && !run.frames.empty()) {
    html << "<p class=\"note\">No frames to show: the query " << HtmlEscape(query_name)
         << " is a live input, a single image or a stream that cannot be read a second time, and this report was "
            "made from the run's file alone (<code>vmap localize --report</code> keeps the last frames of such a "
            "query).</p>\n";
  } else if (written.empty()) {
    html << "<p class=\"note\">No frames to show.</p>\n";
  }
  html << "</div>\n</section>\n" << report::PageEnd();
  WriteFileAtomically(output.path() / kReportFileName, html.str());
  WriteFileAtomically(output.path() / kLocalizationReportRunFileName, LocalizationRunJson(map, run));
  return prepared;
}

namespace {

// The folder goes whole when the report is replaced, report/ with it: a file of the user's inside report/ (notes, an
// exported figure) would go too. A report's report/ holds frames/ and nothing else, and frames/ only NNNNNN.jpg.
std::string WhyNotReportAssets(const fs::path& directory) {
  const fs::path assets = directory / kReportAssetsDirectory;
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(assets, ec);
  if (status.type() == fs::file_type::not_found) return "";
  const auto foreign = [](const std::string& name) {
    return "it holds '" + name + "', which a localization report never holds";
  };
  if (!fs::is_directory(status)) return foreign(kReportAssetsDirectory);
  for (const fs::directory_entry& entry : fs::directory_iterator(assets, ec)) {
    const std::string name = entry.path().filename().string();
    if (name != "frames" || !entry.is_directory() || entry.is_symlink()) {
      return foreign(std::string(kReportAssetsDirectory) + "/" + name);
    }
  }
  if (ec) return "its " + std::string(kReportAssetsDirectory) + " cannot be listed: " + ec.message();
  const fs::path frames = assets / "frames";
  if (!fs::exists(frames)) return "";
  for (const fs::directory_entry& entry : fs::directory_iterator(frames, ec)) {
    const std::string name = entry.path().filename().string();
    const std::string stem = name.size() > 4 ? name.substr(0, name.size() - 4) : "";
    const bool numbered = !stem.empty() && name.compare(stem.size(), 4, ".jpg") == 0 &&
                          stem.find_first_not_of("0123456789") == std::string::npos;
    if (!numbered || !entry.is_regular_file() || entry.is_symlink()) {
      return foreign(std::string(kReportAssetsDirectory) + "/frames/" + name);
    }
  }
  return ec ? "its " + std::string(kReportAssetsDirectory) + "/frames cannot be listed: " + ec.message() : "";
}

}  // namespace

std::string WhyNotALocalizationReport(const fs::path& directory) {
  const ContainedJson parsed =
      ReadContainedJson(directory, kLocalizationReportRunFileName, kMaxRunJsonBytes, kMaxRunJsonValues);
  if (parsed.missing) return std::string("it has no ") + kLocalizationReportRunFileName;
  if (!parsed.document) return "its " + parsed.why_not;
  if (!parsed.document->is_object() || parsed.document->value("format", nlohmann::json()) != "vmap-localization") {
    return std::string("its ") + kLocalizationReportRunFileName + " is not a vmap localization run";
  }
  // A run.json is also what `vmap localize --json DIR/run.json` writes, into a folder that may hold anything else:
  // a report is the folder that holds its page too, and nothing but what a report writes.
  if (!fs::is_regular_file(directory / kReportFileName)) return std::string("it has no ") + kReportFileName;
  std::error_code ec;
  for (const fs::directory_entry& entry : fs::directory_iterator(directory, ec)) {
    const std::string name = entry.path().filename().string();
    if (name != kReportFileName && name != kLocalizationReportRunFileName && name != kReportAssetsDirectory) {
      return "it holds '" + name + "', which a localization report never holds";
    }
  }
  if (ec) return "it cannot be listed: " + ec.message();
  return WhyNotReportAssets(directory);
}

void WriteLocalizationReport(const fs::path& run_file, const fs::path& directory,
                             const LocalizationReportOptions& options) {
  LocalizationRun run = ReadLocalizationRun(run_file);
  // A relative path is relative to where the run was made: looked for from here, beside the run, then as the absolute
  // path the run recorded (a report made from another folder found neither, and advised building a map).
  const auto locate = [&](const fs::path& given, const fs::path& absolute, const fs::path& marker) {
    const auto found = [&](const fs::path& path) {
      std::error_code ec;
      return !path.empty() && fs::exists(marker.empty() ? path : path / marker, ec);
    };
    if (given.empty() || found(given) || !given.is_relative()) return given;
    for (const fs::path& candidate : {run_file.parent_path() / given, absolute}) {
      if (found(candidate)) return candidate;
    }
    return given;
  };
  const fs::path map_directory = locate(run.info.map_directory, run.info.map_absolute_directory, kMapFileName);
  run.info.query = locate(run.info.query, run.info.query_absolute_path, "").string();
  const VisualMap map = ReadMap(map_directory);
  CheckRunFitsMap(run, map, run_file);
  CheckOutputDirectory(directory, ReportPolicy(map_directory, run.info.query, run_file));
  WriteLocalizationReport(run, map, map_directory, directory, options);
}

}  // namespace vmap
