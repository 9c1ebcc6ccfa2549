#include "vmap/report/link_table.h"

#include <cmath>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "vmap/core/error.h"
#include "vmap/evaluation/evaluation_json.h"
#include "vmap/report/html_util.h"

namespace vmap {
namespace fs = std::filesystem;
using report::FormatFixed;
using report::HtmlEscape;

namespace {

std::string Cell(const std::string& text, bool numeric = true) {
  return std::string(numeric ? "<td class=\"num\">" : "<td>") + text + "</td>";
}

std::string Value(double value, int decimals, const std::string& unit = "") {
  return std::isfinite(value) ? FormatFixed(value, decimals) + unit : "&ndash;";
}

std::string Share(double share) { return std::isfinite(share) ? FormatFixed(100.0 * share, 0) + " %" : "&ndash;"; }

}  // namespace

std::optional<MapEvaluation> ReadMatchingEvaluation(const fs::path& map_directory, const VisualMap& map) {
  const fs::path file = map_directory / kEvaluationFileName;
  if (!fs::is_regular_file(file)) return std::nullopt;
  MapEvaluation evaluation;
  try {
    evaluation = ReadEvaluation(file.string());
  } catch (const InputError& e) {
    spdlog::warn("ignoring {}: {}", file.string(), e.what());
    return std::nullopt;
  }
  bool matches = evaluation.links.size() == map.links.size();
  for (size_t i = 0; matches && i < map.links.size(); ++i) {
    const LinkEvaluation& e = evaluation.links[i];
    matches = e.link == static_cast<int>(i) && e.from_frame == map.key_images[map.links[i].from_key].frame_index &&
              e.to_frame == map.key_images[map.links[i].to_key].frame_index;
  }
  if (!matches) {
    spdlog::warn("ignoring {}: it evaluates other links than this map's; run `vmap eval {}` again", file.string(),
                 map_directory.string());
    return std::nullopt;
  }
  return evaluation;
}

std::string EvaluationCaption(const LinkEvaluation& e) {
  if (!e.has_ground_truth) return "no ground truth";
  if (e.pose_source == "none") return "no pose: not usable";
  return fmt::format("rotation error {} deg, translation error {} deg, true parallax {} px: {}",
                     std::isfinite(e.rotation_error_deg) ? FormatFixed(e.rotation_error_deg, 2) : "-",
                     std::isfinite(e.translation_error_deg) ? FormatFixed(e.translation_error_deg, 1) : "-",
                     std::isfinite(e.true_parallax_px) ? FormatFixed(e.true_parallax_px, 1) : "-",
                     e.usable ? "usable" : "NOT usable");
}

std::string LinkTableHtml(const VisualMap& map, const MapEvaluation* evaluation) {
  std::string html = "<section id=\"link-table\"><h2>Links</h2>\n";
  if (map.input.camera) {
    const Camera& c = *map.input.camera;
    html += "<p class=\"note\">Camera " + HtmlEscape(CameraModelName(c.model)) + " " + std::to_string(c.size.width) +
            "x" + std::to_string(c.size.height) + ", fx " + FormatFixed(c.fx, 2) + ", fy " + FormatFixed(c.fy, 2) +
            ", cx " + FormatFixed(c.cx, 2) + ", cy " + FormatFixed(c.cy, 2) +
            (c.has_distortion() ? ", with distortion" : "") +
            (c.origin.empty() ? "" : " (" + HtmlEscape(c.origin) + ")") +
            ". Each link's pose maps the first key image's camera frame to the second's: X<sub>to</sub> = R "
            "X<sub>from</sub> + t, |t| = 1.</p>\n";
  } else {
    html +=
        "<p class=\"note\">The map has no camera: its links have no pose (build with <code>--camera</code> to "
        "get one). The parallax is the plain median displacement of the verified matches.</p>\n";
  }
  if (evaluation) {
    const EvaluationSummary& s = evaluation->summary;
    html += "<div class=\"cards\">";
    for (const auto& [value, label] : std::vector<std::pair<std::string, std::string>>{
             {std::to_string(s.usable_links) + " / " + std::to_string(s.evaluated_links), "usable links"},
             {std::isfinite(s.usable_share) ? FormatFixed(100.0 * s.usable_share, 1) + " %" : "n/a", "usable share"},
             {Value(s.rotation_error_deg_median, 2, "\u00b0"), "median rotation error"},
             {Value(s.translation_error_deg_median, 1, "\u00b0"), "median translation error"},
             {std::to_string(s.strict_usable_links) + " / " + std::to_string(s.evaluated_links),
              "usable with every translation judged"},
             {std::to_string(s.flagged_links) + " (" + std::to_string(s.flagged_wrong_links) + " wrong)",
              "translation unknown (the map's flag)"}}) {
      html += "<div class=\"card\"><div class=\"value\">" + value + "</div><div class=\"label\">" + HtmlEscape(label) +
              "</div></div>";
    }
    html += "</div>\n<p class=\"note\">Against the ground truth " + HtmlEscape(evaluation->ground_truth_path) +
            " (<code>vmap eval</code>). Usable: rotation error below " +
            FormatFixed(evaluation->options.max_rotation_error_deg, 1) +
            "&deg; and, where the true parallax is at least " + FormatFixed(evaluation->options.min_parallax_px, 0) +
            " px, translation direction error below " + FormatFixed(evaluation->options.max_translation_error_deg, 0) +
            "&deg;. Sampson errors are under the true F.</p>\n";
  }
  html +=
      "<table class=\"links-table\"><thead><tr><th class=\"num\">link</th><th>frames</th><th class=\"num\">S</th>"
      "<th class=\"num\">verified / tentative</th><th class=\"num\">parallax</th><th>homography</th>"
      "<th>t (unit)</th><th>translation known (&sigma; of its direction)</th>";
  if (evaluation) {
    html +=
        "<th class=\"num\">rotation error</th><th class=\"num\">translation error</th>"
        "<th class=\"num\">true parallax</th><th class=\"num\">verified on true epipolar line</th>"
        "<th class=\"num\">rejected on true epipolar line</th><th>usable</th>";
  }
  html += "</tr></thead>\n<tbody>\n";
  for (size_t i = 0; i < map.links.size(); ++i) {
    const Link& l = map.links[i];
    const LinkEvaluation* e = evaluation ? &evaluation->links[i] : nullptr;
    const bool bad = e && e->has_ground_truth && !e->usable;
    html += std::string("<tr") + (bad ? " class=\"below-tau\"" : "") + " data-link=\"" + std::to_string(i) + "\">";
    html += Cell("<a href=\"#link-" + std::to_string(i) + "\">" + std::to_string(i) + "</a>");
    html += Cell(std::to_string(map.key_images[l.from_key].frame_index) + " &rarr; " +
                     std::to_string(map.key_images[l.to_key].frame_index) + (l.below_tau ? " (below &tau;)" : ""),
                 false);
    html += Cell(FormatFixed(l.similarity, 3));
    html += Cell(std::to_string(l.num_verified) + " / " + std::to_string(l.num_tentative));
    html += Cell(l.parallax >= 0 ? FormatFixed(l.parallax, 1) + " px" + (l.parallax_without_rotation ? "" : "*")
                                 : "&ndash;");
    html += Cell(l.homography_share >= 0
                     ? (l.planar ? "<b>explains " : "explains ") + FormatFixed(100.0 * l.homography_share, 0) + " %" +
                           (l.planar ? " (plane or rotation)</b>" : "")
                     : "&ndash;",
                 false);
    html += Cell(l.has_pose ? fmt::format("({:.2f}, {:.2f}, {:.2f})", l.t[0], l.t[1], l.t[2]) : "&ndash;", false);
    const std::string sigma =
        l.translation_sigma_deg >= 0 ? " (" + FormatFixed(l.translation_sigma_deg, 1) + "&deg;)" : "";
    html +=
        Cell(!l.has_pose ? "&ndash;" : (l.translation_known ? "yes" + sigma : "<b>no</b>" + sigma + ": rotation only"),
             false);
    if (e) {
      html += Cell(Value(e->rotation_error_deg, 2, "&deg;")) + Cell(Value(e->translation_error_deg, 1, "&deg;")) +
              Cell(Value(e->true_parallax_px, 1, " px")) + Cell(Share(e->verified_within)) +
              Cell(Share(e->rejected_within)) +
              Cell(!e->has_ground_truth ? "no GT" : (e->usable ? "yes" : "<b>no</b>"), false);
    }
    html += "</tr>\n";
  }
  html +=
      "</tbody></table>\n<p class=\"note\">Parallax: median displacement of the verified matches after undoing "
      "the link's rotation (* without a pose: the plain displacement). Homography: the share of the verified "
      "matches one homography explains; when it explains nearly all, the scene is a plane or the camera only "
      "rotated, and F and the pose are ill-posed. Translation known: the standard deviation of t's direction "
      "that the matches allow is small enough to trust it; otherwise a robot gets the link's rotation only "
      "(docs/link-poses.md).</p>\n</section>\n";
  return html;
}

}  // namespace vmap
