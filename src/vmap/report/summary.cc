#include "vmap/report/summary.h"

#include <algorithm>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "vmap/core/contained_file.h"
#include "vmap/core/file_name_encoding.h"
#include "vmap/core/number_text.h"
#include "vmap/report/html_util.h"

namespace vmap {

std::string FormatMapSummary(const VisualMap& map, QualityMean mean) {
  const MapStatistics s = ComputeStatistics(map, mean);
  std::string text;
  text += fmt::format("input           {} ({})\n", map.input.path, SourceFormatName(map.input.format));
  text += fmt::format("frames (n)      {}", s.num_frames);
  if (map.skipped_frames > 0) text += fmt::format("  ({} unusable frames skipped)", map.skipped_frames);
  text += "\n";
  text += fmt::format("key images (m)  {} ({:.1f}% of frames)\n", s.num_key_images,
                      s.num_frames > 0 ? 100.0 * s.num_key_images / s.num_frames : 0.0);
  if (!map.links.empty()) {
    text += fmt::format("verified matches between consecutive key images  min {}  max {}  mean {:.1f}\n",
                        s.min_verified, s.max_verified, s.mean_verified);
    text += fmt::format("mean similarity {:.3f}", s.mean_similarity);
    if (s.below_tau_links > 0) text += fmt::format("  ({} links below tau)", s.below_tau_links);
    text += "\n";
  }
  if (map.input.camera) {
    const Camera& c = *map.input.camera;
    text += fmt::format(
        "camera          {} {}x{} fx {:.2f} fy {:.2f} cx {:.2f} cy {:.2f}{}; links with a pose {} of {}\n",
        CameraModelName(c.model), c.size.width, c.size.height, c.fx, c.fy, c.cx, c.cy,
        c.has_distortion() ? " (with distortion)" : "",
        std::count_if(map.links.begin(), map.links.end(), [](const Link& l) { return l.has_pose; }), map.links.size());
    const auto known = std::count_if(map.links.begin(), map.links.end(),
                                     [](const Link& l) { return l.has_pose && l.translation_known; });
    text += fmt::format("translation     known on {} of {} links; the others give a robot their rotation only\n", known,
                        map.links.size());
  }
  if (!map.camera_mask.empty()) {
    text += fmt::format("camera mask     {}x{}, features on {:.1f}% of the pixels (camera_mask.png)\n",
                        map.camera_mask.cols, map.camera_mask.rows,
                        100.0 * cv::countNonZero(map.camera_mask) / double(map.camera_mask.total()));
  }
  text += fmt::format("quality Q       {:.4f} ({} mean)\n", s.quality, QualityMeanName(mean));
  if (map.seconds > 0) {
    text += fmt::format("time            {:.2f} s ({:.1f} frames/s)\n", map.seconds, s.num_frames / map.seconds);
  }
  return text;
}

namespace {

// A threshold as the user gave it: two decimals (0.50), more where two would read two thresholds alike (0.101, 0.104).
std::string TauText(double tau) {
  const std::string two = fmt::format("{:.2f}", tau);
  return std::stod(two) == tau ? two : fmt::format("{:.12g}", tau);
}

// A threshold in sweep.csv: four decimals (0.3000), all its digits where four would not read back as it (0.12341
// and 0.12344 both read 0.1234, and the rows could not be told apart nor matched with sweep.json's).
std::string CsvTau(double tau) {
  const std::string four = fmt::format("{:.4f}", tau);
  return ParseNumber(four) == tau ? four : report::FormatExact(tau);
}

}  // namespace

std::string SweepToMarkdown(const SweepResult& sweep) {
  std::string text =
      fmt::format("Threshold sweep of {} ({} frames, {:.1f} s)\n\n", sweep.input.path, sweep.num_frames, sweep.seconds);
  const bool has_usable =
      std::any_of(sweep.rows.begin(), sweep.rows.end(), [](const SweepRow& r) { return r.usable_links >= 0; });
  text += "| tau | key images | % frames | min matches | max matches | mean matches | mean S | Q |";
  text += has_usable ? " usable links |\n" : "\n";
  text +=
      has_usable ? "|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n" : "|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (size_t i = 0; i < sweep.rows.size(); ++i) {
    const SweepRow& r = sweep.rows[i];
    const bool best = static_cast<int>(i) == sweep.best_row;
    text +=
        fmt::format("| {}{}{} | {} | {:.1f} | {} | {} | {:.1f} | {:.3f} | {}{:.4f}{} |", best ? "**" : "",
                    TauText(r.tau), best ? "**" : "", r.num_key_images, r.key_image_percent, r.min_verified,
                    r.max_verified, r.mean_verified, r.mean_similarity, best ? "**" : "", r.quality, best ? "**" : "");
    if (has_usable) {
      const int links = std::max(0, r.num_key_images - 1);
      text += r.usable_links < 0 ? " - |"
                                 : fmt::format(" {} of {} ({:.0f}%) |", r.usable_links, links,
                                               links > 0 ? 100.0 * r.usable_links / links : 0.0);
    }
    text += "\n";
  }
  if (sweep.best_row >= 0) text += fmt::format("\nBest tau by Q: {}\n", TauText(sweep.rows[sweep.best_row].tau));
  return text;
}

std::string SweepToCsv(const SweepResult& sweep) {
  std::string text =
      "tau,key_images,key_image_percent,min_matches,max_matches,mean_matches,mean_similarity,quality,"
      "below_tau_links,usable_links,best\n";
  for (size_t i = 0; i < sweep.rows.size(); ++i) {
    const SweepRow& r = sweep.rows[i];
    text += fmt::format("{},{},{:.4f},{},{},{:.4f},{:.6f},{:.6f},{},{},{}\n", CsvTau(r.tau), r.num_key_images,
                        r.key_image_percent, r.min_verified, r.max_verified, r.mean_verified, r.mean_similarity,
                        r.quality, r.below_tau_links, r.usable_links >= 0 ? std::to_string(r.usable_links) : "",
                        static_cast<int>(i) == sweep.best_row ? 1 : 0);
  }
  return text;
}

std::string SweepToJson(const SweepResult& sweep) {
  nlohmann::json doc;
  doc["format"] = "vmap-sweep";
  doc["schema_version"] = 1;
  doc["input"] = {{"path", EncodeFileName(sweep.input.path)}, {"format", SourceFormatName(sweep.input.format)}};
  doc["options"] = sweep.options_json.empty() ? nlohmann::json::object() : nlohmann::json::parse(sweep.options_json);
  doc["num_frames"] = sweep.num_frames;
  doc["seconds"] = sweep.seconds;
  doc["features_extracted"] = sweep.features_extracted;
  doc["pairs_matched"] = sweep.pairs_matched;
  doc["best_tau"] = sweep.best_row >= 0 ? nlohmann::json(sweep.rows[sweep.best_row].tau) : nlohmann::json(nullptr);
  nlohmann::json rows = nlohmann::json::array();
  for (const SweepRow& r : sweep.rows) {
    rows.push_back(
        {{"tau", r.tau},
         {"key_images", r.num_key_images},
         {"key_image_percent", r.key_image_percent},
         {"min_matches", r.min_verified},
         {"max_matches", r.max_verified},
         {"mean_matches", r.mean_verified},
         {"mean_similarity", r.mean_similarity},
         {"quality", r.quality},
         {"below_tau_links", r.below_tau_links},
         {"usable_links", r.usable_links >= 0 ? nlohmann::json(r.usable_links) : nlohmann::json(nullptr)},
         {"map", r.map_directory.empty() ? nlohmann::json(nullptr) : nlohmann::json(EncodeFileName(r.map_directory))}});
  }
  doc["rows"] = rows;
  return doc.dump(1) + "\n";
}

std::string WhyNotAVmapSweep(const std::filesystem::path& directory) {
  // sweep.json is a table of some hundred lines: 64 MB is far more than any.
  const ContainedJson parsed = ReadContainedJson(directory, kSweepJsonFileName, 64ull << 20, 1ull << 22);
  if (parsed.missing) return "it has no sweep.json";
  if (!parsed.document) return "its " + parsed.why_not;
  const nlohmann::json& doc = *parsed.document;
  if (!doc.is_object() || doc.value("format", nlohmann::json()) != "vmap-sweep") {
    return "its sweep.json is not a vmap sweep's: it has no \"format\": \"vmap-sweep\"";
  }
  if (!doc.value("schema_version", nlohmann::json()).is_number_integer()) {
    return "its sweep.json has no integer \"schema_version\"";
  }
  return "";
}

}  // namespace vmap
