#include "vmap/report/evaluation_summary.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace vmap {

namespace {

std::string Fixed(double value, int decimals, int width) {
  if (!std::isfinite(value)) return fmt::format("{:>{}}", "-", width);
  return fmt::format("{:>{}.{}f}", value, width, decimals);
}

std::string Percent(double share, int width) {
  if (!std::isfinite(share)) return fmt::format("{:>{}}", "-", width);
  return fmt::format("{:>{}.0f}%", 100.0 * share, std::max(0, width - 1));
}

}  // namespace

std::string FormatEvaluationTable(const MapEvaluation& evaluation) {
  const double within = evaluation.options.sampson_threshold_px;
  std::string text = fmt::format(
      "| link | input frames |   S   | verified | ver. Sampson | ver. <{:g}px | rej. Sampson | rej. <{:g}px | rot. err "
      "| transl. err | true parallax | t sigma | t known | pose        | usable |\n",
      within, within);
  text += "|---:|:---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|:---:|:---|:---:|\n";
  for (const LinkEvaluation& e : evaluation.links) {
    std::string notes;
    if (e.below_tau) notes += " below-tau";
    if (e.planar) notes += " planar";
    text += fmt::format(
        "| {:>4} | {:>6}-{:<5} | {:.3f} | {:>8} | {} px | {} | {} px | {} | {} deg | {} deg | {} px | {} deg | {:^7} "
        "| {:<11} | {:^6} |{}\n",
        e.link, e.from_source, e.to_source, e.similarity, e.num_verified, Fixed(e.verified_sampson_median, 2, 9),
        Percent(e.verified_within, 10), Fixed(e.rejected_sampson_median, 2, 9), Percent(e.rejected_within, 10),
        Fixed(e.rotation_error_deg, 2, 4), Fixed(e.translation_error_deg, 1, 7), Fixed(e.true_parallax_px, 1, 10),
        Fixed(e.translation_sigma_deg, 1, 4), e.translation_known ? "yes" : "no", e.pose_source,
        !e.has_ground_truth ? "no GT" : (e.usable ? "yes" : "NO"), notes);
  }
  return text;
}

std::string FormatEvaluationSummary(const MapEvaluation& evaluation) {
  const EvaluationSummary& s = evaluation.summary;
  const EvaluationOptions& o = evaluation.options;
  std::string text;
  text += fmt::format("ground truth    {} ({})\n", evaluation.ground_truth_path,
                      GroundTruthFormatName(evaluation.ground_truth_format));
  text += fmt::format("camera          {} {}x{} fx {:.2f} fy {:.2f} cx {:.2f} cy {:.2f}{}\n",
                      CameraModelName(evaluation.camera.model), evaluation.camera.size.width,
                      evaluation.camera.size.height, evaluation.camera.fx, evaluation.camera.fy, evaluation.camera.cx,
                      evaluation.camera.cy, evaluation.camera.has_distortion() ? " (with distortion)" : "");
  text += fmt::format("links           {} ({} with ground truth for both key images, {} with a pose)\n", s.links,
                      s.evaluated_links, s.links_with_pose);
  text += fmt::format(
      "usable links    {} of {}{}{}  (rotation error < {:g} deg; translation error < {:g} deg where "
      "the true parallax >= {:g} px)\n",
      s.usable_links, s.evaluated_links,
      std::isfinite(s.usable_share) ? fmt::format(" = {:.1f}%", 100.0 * s.usable_share) : "",
      s.evaluated_links < s.links ? fmt::format(" with ground truth; {} links have none", s.links - s.evaluated_links)
                                  : "",
      o.max_rotation_error_deg, o.max_translation_error_deg, o.min_parallax_px);
  const auto of = [](int part, int whole, double share) {
    return fmt::format("{} of {}{}", part, whole, std::isfinite(share) ? fmt::format(" = {:.1f}%", 100.0 * share) : "");
  };
  text += fmt::format("strictly usable {}  (every link's translation judged)\n",
                      of(s.strict_usable_links, s.evaluated_links, s.strict_usable_share));
  text += fmt::format("translation unknown (the map's flag)  {} links, wrong {}\n", s.flagged_links,
                      of(s.flagged_wrong_links, s.flagged_links, s.flagged_wrong_share));
  text += fmt::format("translation known  {} links, right {}, usable {}, more than 90 deg off {}\n", s.unflagged_links,
                      of(s.unflagged_right_links, s.unflagged_links, s.unflagged_right_share),
                      of(s.unflagged_usable_links, s.unflagged_links, s.unflagged_usable_share),
                      s.unflagged_reversed_links);
  text += fmt::format("rotation error  median {} deg\n", Fixed(s.rotation_error_deg_median, 3, 0));
  text += fmt::format("translation error  median {} deg (links with true parallax >= {:g} px)\n",
                      Fixed(s.translation_error_deg_median, 2, 0), o.min_parallax_px);
  text += fmt::format("matches within {:g} px of the true epipolar line  verified {}  rejected {}\n",
                      o.sampson_threshold_px, Percent(s.verified_within_mean, 0), Percent(s.rejected_within_mean, 0));
  return text;
}

}  // namespace vmap
