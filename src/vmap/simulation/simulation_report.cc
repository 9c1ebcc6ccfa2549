// The HTML report of a simulation (simulation_output.h): one page with inline SVG, no scripts, opens offline.

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "vmap/core/atomic_output.h"
#include "vmap/report/html_util.h"
#include "vmap/simulation/simulation_output.h"

namespace vmap {

namespace {

using report::HtmlEscape;

std::string Metres(double value) { return std::isfinite(value) ? fmt::format("{:.3f}", value) : "-"; }

// Every trial's lateral error (m) against the distance along the route (m), +-0.1 m marked.
std::string LateralErrorSvg(const SimulationResult& result) {
  const int width = 900, height = 320, left = 50, right = 10, top = 10, bottom = 30;
  const double length = std::max(1e-3, result.route.path.length());
  double limit = 0.2;
  for (const TrialResult& trial : result.trials) limit = std::max(limit, trial.lateral_max);
  limit = std::min(limit, 2.0);
  auto x_of = [&](double s) { return left + (width - left - right) * std::clamp(s / length, 0.0, 1.0); };
  auto y_of = [&](double lateral) {
    return top + (height - top - bottom) * (0.5 - 0.5 * std::clamp(lateral / limit, -1.0, 1.0));
  };
  std::string svg =
      fmt::format(R"(<svg xmlns="http://www.w3.org/2000/svg" width="{}" height="{}" font-size="11">)", width, height);
  svg += fmt::format(R"(<rect x="{}" y="{}" width="{}" height="{}" fill="none" stroke="#999"/>)", left, top,
                     width - left - right, height - top - bottom);
  for (const double band : {0.1, -0.1}) {
    svg += fmt::format(R"(<line x1="{}" x2="{}" y1="{:.1f}" y2="{:.1f}" stroke="#888" stroke-dasharray="4 3"/>)", left,
                       width - right, y_of(band), y_of(band));
  }
  svg += fmt::format(R"(<line x1="{}" x2="{}" y1="{:.1f}" y2="{:.1f}" stroke="#bbb"/>)", left, width - right, y_of(0),
                     y_of(0));
  svg += fmt::format(R"(<line x1="{:.1f}" x2="{:.1f}" y1="{}" y2="{}" stroke="#bbb" stroke-dasharray="2 3"/>)",
                     x_of(0.5 * length), x_of(0.5 * length), top, height - bottom);
  for (const TrialResult& trial : result.trials) {
    std::string points;
    for (const TrialSample& sample : trial.samples)
      points += fmt::format("{:.1f},{:.1f} ", x_of(sample.s), y_of(sample.lateral));
    svg += fmt::format(R"(<polyline fill="none" stroke="{}" stroke-width="1" stroke-opacity="0.6" points="{}"/>)",
                       trial.success ? "#2a9d3c" : "#d73027", points);
  }
  for (const double tick : {-limit, -0.1, 0.0, 0.1, limit}) {
    svg += fmt::format(R"(<text x="{}" y="{:.1f}" text-anchor="end">{:.2f}</text>)", left - 4, y_of(tick) + 4, tick);
  }
  for (int k = 0; k <= 4; ++k) {
    svg += fmt::format(R"(<text x="{:.1f}" y="{}" text-anchor="middle">{:.1f} m</text>)", x_of(length * k / 4),
                       height - 10, length * k / 4);
  }
  return svg + "</svg>";
}

}  // namespace

void WriteSimulationReport(const SimulationResult& result, const SimulationOptions& options,
                           const std::filesystem::path& directory) {
  const cv::Mat top_view = DrawTopView(result, options);
  std::vector<unsigned char> png;
  cv::imencode(".png", top_view, png);
  WriteFileAtomically(directory / "top_view.png",
                      std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
  const SimulationSummary& s = result.summary;
  std::string html = R"(<!doctype html><html><head><meta charset="utf-8"><title>vmap simulate</title><style>
body{font-family:sans-serif;margin:2em;max-width:960px}table{border-collapse:collapse}td,th{padding:2px 8px;border-bottom:1px solid #ddd;text-align:right}
th{background:#f4f4f4}.fail{color:#c00}h2{margin-top:1.5em}</style></head><body>)";
  html += fmt::format("<h1>vmap simulate: {}</h1>", HtmlEscape(result.route.name));
  html += "<table>";
  auto row = [&](const std::string& name, const std::string& value) {
    html += fmt::format("<tr><th style='text-align:left'>{}</th><td style='text-align:left'>{}</td></tr>", name, value);
  };
  row("route", fmt::format("{} ({:.1f} m{})", HtmlEscape(result.route.name), result.route.path.length(),
                           result.route.corridor.closed() ? ", closed corridor" : ""));
  row("matcher, law", fmt::format("{}, {}", HtmlEscape(result.matcher), ControlLawName(options.controller.law)));
  row("teach run",
      fmt::format("{} frames, {} key images, {:.1f} s", result.teach_frames, result.key_images, result.teach_seconds));
  row("reached the goal", fmt::format("{} of {} ({:.1f} %) within {} m", s.successes, s.trials, 100.0 * s.success_rate,
                                      options.goal_tolerance));
  row("final error", fmt::format("{} m mean", Metres(s.mean_final_error)));
  row("lateral error, second half",
      fmt::format("RMS {} m mean, {} m worst; {:.1f} % of trials at most 0.1 m", Metres(s.mean_lateral_rms_second_half),
                  Metres(s.worst_lateral_rms_second_half), 100.0 * s.share_converged));
  row("frames lost", fmt::format("{} of {}", s.frames_lost, s.frames));
  row("control step", fmt::format("{:.1f} ms mean, {:.1f} ms max (features, localization, control)",
                                  1e3 * s.mean_step_seconds, 1e3 * s.max_step_seconds));
  row("rendering",
      fmt::format("{:.0f} frames/s ({}x{})", s.render_frames_per_second, options.camera.width, options.camera.height));
  html += "</table>";
  html +=
      "<h2>From above</h2><p>The corridor (grey), the taught path and its key images (blue), each repeat (green: "
      "reached the goal, red: did not), the goal's tolerance (black circle).</p><img src='top_view.png' "
      "style='max-width:100%'>";
  html +=
      "<h2>Lateral error against the distance along the route</h2><p>Left of the taught path positive; dashed: "
      "+-0.1 m and half the route (the second half is where the lateral RMS is measured).</p>";
  html += LateralErrorSvg(result);
  html +=
      "<h2>Trials</h2><table><tr><th>#</th><th>start lateral (m)</th><th>start heading (deg)</th><th>end</th>"
      "<th>final error (m)</th><th>lateral RMS, 2nd half (m)</th><th>lateral max (m)</th><th>settled at (m)</th>"
      "<th>frames lost</th><th>step (ms)</th></tr>";
  for (const TrialResult& t : result.trials) {
    html += fmt::format(
        "<tr{}><td>{}</td><td>{:.3f}</td><td>{:.1f}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{} "
        "of "
        "{}</td><td>{:.1f}</td></tr>",
        t.success ? "" : " class='fail'", t.index, t.start_lateral, t.start_heading_deg, HtmlEscape(t.end),
        Metres(t.final_error), Metres(t.lateral_rms_second_half), Metres(t.lateral_max), Metres(t.settled_at),
        t.frames_lost, t.frames, 1e3 * t.mean_step_seconds);
  }
  html += "</table></body></html>\n";
  WriteFileAtomically(directory / "report.html", html);
}

}  // namespace vmap
