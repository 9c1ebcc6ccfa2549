// The HTML report of a threshold sweep (`vmap sweep --report`): its summary, the table of every tau and the
// plots of m, Q and S against tau. A map's own report is html_report.cc.
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
#include "vmap/report/html_report.h"
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

// "0.30" as in the paper's tables; a finer threshold keeps all its digits.
std::string TauText(double tau) {
  return std::abs(tau * 100 - std::round(tau * 100)) < 1e-9 ? FormatFixed(tau, 2) : FormatExact(tau);
}

// Where the page in `report_directory` should point for a map written at `map_directory`.
std::string MapLink(const std::string& map_directory, const fs::path& report_directory) {
  fs::path target(map_directory);
  if (target.is_relative() && fs::exists(report_directory / target)) target = report_directory / target;
  std::error_code ec;
  const fs::path absolute_target = fs::weakly_canonical(fs::absolute(target), ec);
  const fs::path absolute_base = fs::weakly_canonical(fs::absolute(report_directory), ec);
  fs::path relative = absolute_target.lexically_relative(absolute_base);
  if (relative.empty()) relative = absolute_target;
  const fs::path page =
      fs::exists(absolute_target / kReportFileName) ? relative / kReportFileName : relative / kMapFileName;
  return UrlPath(page.generic_string());
}

bool HasBestRow(const SweepResult& sweep) {
  return sweep.best_row >= 0 && sweep.best_row < static_cast<int>(sweep.rows.size());
}

// Cards, then the input, matcher, verifier and work done.
std::string SweepSummarySection(const SweepResult& sweep, const json& options) {
  const bool has_best = HasBestRow(sweep);
  std::ostringstream html;
  html << "<section id=\"summary\"><h2>Summary</h2>\n<div class=\"cards\">"
       << Card(std::to_string(sweep.num_frames), "frames (n)") << Card(std::to_string(sweep.rows.size()), "thresholds")
       << (has_best ? Card(TauText(sweep.rows[sweep.best_row].tau), "best \u03c4 (highest Q)") +
                          Card(FormatFixed(sweep.rows[sweep.best_row].quality, 3), "best Q")
                    : "")
       << "</div>\n<table class=\"summary\">\n"
       << Row("Input", HtmlEscape(Displayable(sweep.input.path)))
       << Row("Format", HtmlEscape(SourceFormatName(sweep.input.format)))
       << Row("Frame size", HtmlEscape(SizeText(sweep.input.frame_size)))
       << Row("Matcher", HtmlEscape(OptionText(options, "matcher")))
       << Row("Verifier", HtmlEscape(OptionText(options, "verifier")))
       << Row("Features extracted", std::to_string(sweep.features_extracted))
       << Row("Pairs matched", std::to_string(sweep.pairs_matched)) << Row("Time", DurationText(sweep.seconds))
       << "</table>\n</section>\n";
  return html.str();
}

// One row per threshold; the best one starred, rows with links below tau shaded.
std::string SweepTableSection(const SweepResult& sweep, const fs::path& report_directory) {
  const bool has_best = HasBestRow(sweep);
  std::ostringstream html;
  const bool has_usable =
      std::any_of(sweep.rows.begin(), sweep.rows.end(), [](const SweepRow& r) { return r.usable_links >= 0; });
  html << "<section id=\"table\"><h2>Key images and quality per threshold</h2>\n<table class=\"sweep\">\n<thead><tr>"
          "<th class=\"num\">&tau;</th><th class=\"num\">key images m</th><th class=\"num\">% of frames</th>"
          "<th class=\"num\">min</th><th class=\"num\">max</th><th class=\"num\">mean verified</th>"
          "<th class=\"num\">mean S</th><th class=\"num\">Q</th><th class=\"num\">links below &tau;</th>"
       << (has_usable ? "<th class=\"num\">usable links (ground truth)</th>" : "")
       << "<th>map</th>"
          "</tr></thead>\n<tbody>\n";
  for (size_t i = 0; i < sweep.rows.size(); ++i) {
    const SweepRow& r = sweep.rows[i];
    const bool best = has_best && static_cast<int>(i) == sweep.best_row;
    html << "<tr class=\"" << (best ? "best" : (r.below_tau_links > 0 ? "below-tau" : "")) << "\" data-tau=\""
         << FormatExact(r.tau) << "\"><td class=\"num\">" << (best ? "&#9733; " : "") << TauText(r.tau)
         << "</td><td class=\"num\">" << r.num_key_images << "</td><td class=\"num\">"
         << FormatFixed(r.key_image_percent, 1) << "</td><td class=\"num\">" << r.min_verified
         << "</td><td class=\"num\">" << r.max_verified << "</td><td class=\"num\">" << FormatFixed(r.mean_verified, 1)
         << "</td><td class=\"num\">" << FormatFixed(r.mean_similarity, 3) << "</td><td class=\"num\">"
         << FormatFixed(r.quality, 4) << "</td><td class=\"num\">" << r.below_tau_links << "</td>";
    if (has_usable) {
      html << "<td class=\"num\">"
           << (r.usable_links >= 0 ? std::to_string(r.usable_links) + " of " + std::to_string(r.num_key_images - 1)
                                   : std::string("-"))
           << "</td>";
    }
    html << "<td>";
    if (!r.map_directory.empty()) {
      html << "<a class=\"map-link\" href=\"" << HtmlEscape(MapLink(r.map_directory, report_directory)) << "\">"
           << HtmlEscape(fs::path(r.map_directory).filename().string()) << "</a>";
    }
    html << "</td></tr>\n";
  }
  html << "</tbody></table>\n"
       << (has_best ? "<p class=\"note\">&#9733; marks the threshold with the highest Q. Rows with links below &tau; "
                      "are shaded red. "
                      "A map without a page links to its map.json: <code>vmap report DIR</code> makes its page.</p>\n"
                    : "")
       << "</section>\n";
  return html.str();
}

// Key images, Q, mean S and the compression against tau.
std::string SweepPlotsSection(const SweepResult& sweep) {
  const bool has_best = HasBestRow(sweep);
  SvgPlot keys_plot("keys-plot", "threshold \u03c4", "key images m");
  keys_plot.SetSize(720, 320);
  keys_plot.SetIntegerY(true);
  SvgPlot quality_plot("quality-plot", "threshold \u03c4", "value");
  quality_plot.SetSize(720, 320);
  PlotSeries keys_line, quality_line, similarity_line, compression_line;
  keys_line.name = "key images m";
  keys_line.color = kBlue;
  keys_line.css_class = "key-images";
  quality_line.name = "Q";
  quality_line.color = kGreen;
  quality_line.css_class = "quality";
  similarity_line.name = "mean S";
  similarity_line.color = kOrange;
  similarity_line.css_class = "similarity";
  compression_line.name = "1 \u2212 m/n";
  compression_line.color = kGrey;
  compression_line.css_class = "compression";
  for (PlotSeries* s : {&keys_line, &quality_line, &similarity_line, &compression_line}) s->segments.emplace_back();
  double y_high = 1.0;
  // Drawn in the order of tau, not in the order the thresholds were given (0.5,0.2,0.35 drew a zigzag).
  std::vector<const SweepRow*> by_tau;
  for (const SweepRow& r : sweep.rows) by_tau.push_back(&r);
  std::stable_sort(by_tau.begin(), by_tau.end(), [](const SweepRow* a, const SweepRow* b) { return a->tau < b->tau; });
  for (const SweepRow* row : by_tau) {
    const SweepRow& r = *row;
    keys_line.segments[0].emplace_back(r.tau, r.num_key_images);
    quality_line.segments[0].emplace_back(r.tau, r.quality);
    similarity_line.segments[0].emplace_back(r.tau, r.mean_similarity);
    compression_line.segments[0].emplace_back(
        r.tau, sweep.num_frames > 0 ? 1.0 - static_cast<double>(r.num_key_images) / sweep.num_frames : 0.0);
    y_high = std::max({y_high, r.quality, r.mean_similarity});
  }
  quality_plot.SetYRange(0.0, y_high);
  auto markers_of = [](PlotSeries line) {
    line.kind = PlotSeries::Kind::kMarkers;
    line.name.clear();
    line.css_class += "-points";
    return line;
  };
  keys_plot.Add(keys_line);
  keys_plot.Add(markers_of(keys_line));
  quality_plot.Add(compression_line);
  quality_plot.Add(similarity_line);
  quality_plot.Add(quality_line);
  quality_plot.Add(markers_of(quality_line));
  if (has_best) {
    const SweepRow& best = sweep.rows[sweep.best_row];
    PlotSeries best_keys;
    best_keys.kind = PlotSeries::Kind::kMarkers;
    best_keys.name = "best \u03c4 = " + FormatExact(best.tau);
    best_keys.color = kRed;
    best_keys.css_class = "best";
    best_keys.marker_radius = 6.0;
    best_keys.segments.push_back({cv::Point2d(best.tau, best.num_key_images)});
    keys_plot.Add(best_keys);
    best_keys.segments = {{cv::Point2d(best.tau, best.quality)}};
    quality_plot.Add(best_keys);
  }
  std::ostringstream html;
  html << "<section id=\"plots\"><h2>Key images and quality against &tau;</h2>\n<div class=\"plots\">"
       << keys_plot.Render() << quality_plot.Render() << "</div>\n"
       << "<p class=\"note\">Q is the mean of the compression 1 - m/n and the mean similarity of consecutive key "
          "images; the best threshold balances few key images against well-connected ones.</p>\n</section>\n";
  return html.str();
}

}  // namespace

void WriteSweepReport(const SweepResult& sweep, const fs::path& directory) {
  const json options = ParseOptions(sweep.options_json);
  // Not created here: the CLI writes into a temporary output (AtomicOutputDirectory), which an interruption
  // removes and nothing may bring back.
  std::error_code ec;
  if (!fs::is_directory(directory, ec)) {
    throw InputError("the report directory '" + directory.string() +
                     "' does not exist; create it or write the report elsewhere");
  }
  const std::string input_name = sweep.input.path.empty() ? std::string("the input") : Displayable(sweep.input.path);
  const bool has_best = HasBestRow(sweep);
  std::ostringstream html;
  html << PageStart("vmap sweep: " + input_name, "Threshold sweep of " + input_name,
                    std::to_string(sweep.rows.size()) + " thresholds over " + std::to_string(sweep.num_frames) +
                        " frames" + (has_best ? ", best \u03c4 = " + TauText(sweep.rows[sweep.best_row].tau) : ""),
                    {{"summary", "Summary"}, {"table", "Table"}, {"plots", "Plots"}, {"options", "Options"}});

  html << SweepSummarySection(sweep, options) << SweepTableSection(sweep, directory) << SweepPlotsSection(sweep);
  html << OptionsSection(options, "Every option used for the sweep");
  html << PageEnd();
  WriteFileAtomically(directory / kReportFileName, html.str());
}

}  // namespace vmap
