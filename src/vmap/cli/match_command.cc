// vmap match IMAGE0 IMAGE1: one pair through a matcher and the verifier, to try a matcher on one's own
// images and to compare matches across implementations, and the heading of IMAGE1 against IMAGE0
// (geometry/heading.h; docs/seasons.md).

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "vmap/cli/commands.h"
#include "vmap/cli/option_binder.h"
#include "vmap/core/atomic_output.h"
#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/core/file_name_encoding.h"
#include "vmap/core/image_header.h"
#include "vmap/geometry/heading.h"
#include "vmap/mapping/pair_match.h"
#include "vmap/pipelines/match_pipeline.h"
#include "vmap/pipelines/output_policies.h"
#include "vmap/sources/dataset_camera.h"

namespace vmap::cli {

namespace {

struct MatchFlags {
  std::string image0, image1, json_path;
  std::string camera;  // --camera: "" = none
  bool list = false;
  PairMatchOptions pair;
  OptionFlags option_flags;
};

cv::Mat ReadGray(const std::string& path) {
  // IMREAD_GRAYSCALE, not cvtColor: the decoder's conversion is what the reference implementations see.
  // A FIFO or a device is refused before OpenCV opens it (and would wait or read forever).
  std::string why_not;
  const std::optional<ContainedFile> file = ContainedFile::OpenRegular(path, &why_not);
  if (!file) throw InputError("image '" + path + "' " + why_not + "; give an image file");
  // The size its header announces, before a decoder allocates for it.
  if (const std::optional<cv::Size> announced = ImageHeaderSize(*file)) {
    const std::string problem = FrameSizeProblem(*announced);
    if (!problem.empty()) {
      throw InputError("image '" + path + "' is " + std::to_string(announced->width) + "x" +
                       std::to_string(announced->height) + " (from its header), " + problem +
                       "; give images of a usable size");
    }
  }
  cv::Mat gray;
  try {
    gray = cv::imread(path, cv::IMREAD_GRAYSCALE);
  } catch (const cv::Exception& e) {
    throw InputError("cannot read image '" + path + "' (" + LibraryMessage(e) +
                     "); check that it is an image of a usable size");
  }
  if (gray.empty()) throw InputError("cannot read image '" + path + "'; check the path and that it is an image");
  const std::string size_problem = FrameSizeProblem(gray.size());
  if (!size_problem.empty()) {
    throw InputError("image '" + path + "' is " + std::to_string(gray.cols) + "x" + std::to_string(gray.rows) + ", " +
                     size_problem + "; give images of a usable size");
  }
  return gray;
}

// The image ReadGray accepted, decoded as 8-bit BGR as upstream's models read files (a grey file gives three
// equal channels).
cv::Mat ReadColor(const std::string& path, cv::Size size) {
  cv::Mat bgr;
  try {
    bgr = cv::imread(path, cv::IMREAD_COLOR);
  } catch (const cv::Exception& e) {
    throw InputError("cannot read image '" + path + "' (" + LibraryMessage(e) + "); check that it is an image");
  }
  if (bgr.size() != size) throw InputError("image '" + path + "' changed while it was read; read it again");
  return bgr;
}

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The camera of --camera for images of `size`; both images must have that size for a bearing to mean one thing.
std::optional<Camera> CameraOf(const MatchFlags& flags, cv::Size size0, cv::Size size1) {
  if (flags.camera.empty()) return std::nullopt;
  if (size0 != size1) {
    throw InputError("--camera needs both images at one size, but they are " + std::to_string(size0.width) + "x" +
                     std::to_string(size0.height) + " and " + std::to_string(size1.width) + "x" +
                     std::to_string(size1.height) + "; resize one, or leave out --camera for a heading in pixels");
  }
  return CameraForFrames(ParseCameraOption(flags.camera), size0, size0);
}

nlohmann::json NumberOrNull(double value) { return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(); }

void RunMatch(const MatchFlags& flags) {
  flags.pair.Check();
  const VerifierOptions& verifier = flags.pair.verifier;
  CheckOutputs({{flags.json_path, "--json"}},
               {NamedInput(flags.image0, "the input image"), NamedInput(flags.image1, "the input image")});
  const cv::Mat gray0 = ReadGray(flags.image0), gray1 = ReadGray(flags.image1);
  const std::optional<Camera> camera = CameraOf(flags, gray0.size(), gray1.size());
  auto start = std::chrono::steady_clock::now();
  const std::unique_ptr<Matcher> matcher = CreateMatcher(flags.pair.matcher);
  const double load_s = Seconds(start);

  // Extraction, matching and verification: the library's, as the Python module's vmap.match runs them.
  // Decoded again in colour only for a matcher that reads colour: the grey image stays the decoder's.
  auto with_color = [&](const cv::Mat& gray, const std::string& path) {
    return matcher->reads_color() ? PairImage(gray, ReadColor(path, gray.size())) : PairImage(gray);
  };
  const PairMatch pair = MatchPair(*matcher, with_color(gray0, flags.image0), with_color(gray1, flags.image1), verifier,
                                   flags.pair.heading, camera ? &*camera : nullptr);
  const TentativeMatches& matches = pair.matches;
  const FundamentalResult& fundamental = pair.fundamental;
  const double similarity = pair.similarity;
  const double extract_s = pair.extract_seconds, match_s = pair.match_seconds, verify_s = pair.verify_seconds;
  const HeadingEstimate& heading = pair.heading;
  const double heading_s = pair.heading_seconds;

  std::printf("matcher     %s %s\n", matcher->name().c_str(), matcher->DescribeOptionsJson().c_str());
  std::printf("images      %s (%dx%d), %s (%dx%d)\n", flags.image0.c_str(), gray0.cols, gray0.rows,
              flags.image1.c_str(), gray1.cols, gray1.rows);
  std::printf("tentative   %zu\n", matches.size());
  std::printf("verified    %d (%s, S = %.4f)\n", fundamental.num_inliers,
              fundamental.success ? "F found" : "no F: too few matches or no model", similarity);
  if (fundamental.success) {
    for (int r = 0; r < 3; ++r) {
      std::printf("%s [% .9e % .9e % .9e]\n", r == 0 ? "F          " : "           ", fundamental.F(r, 0),
                  fundamental.F(r, 1), fundamental.F(r, 2));
    }
  }
  if (heading.valid()) {
    std::printf("heading     %.1f px%s (%s: %d of %d matches, confidence %.3f)\n", heading.px,
                camera ? fmt::format(", {:.3f} deg", heading.deg).c_str() : "",
                HeadingMethodName(heading.method).c_str(), heading.votes, heading.num_voters, heading.confidence);
  } else {
    std::printf("heading     none (fewer than %d matches agree)\n", flags.pair.heading.min_votes);
  }
  std::printf("time        load %.3f s, extract %.3f s (2 images), match %.3f s, verify %.3f s, heading %.4f s\n",
              load_s, extract_s, match_s, verify_s, heading_s);
  if (flags.list) {
    std::printf("# x0 y0 x1 y1 score inlier\n");
    for (size_t k = 0; k < matches.size(); ++k) {
      std::printf("%.3f %.3f %.3f %.3f %.6g %d\n", matches.points0[k].x, matches.points0[k].y, matches.points1[k].x,
                  matches.points1[k].y, matches.scores.empty() ? 0.0 : matches.scores[k],
                  fundamental.success ? int(fundamental.inlier_mask[k]) : 0);
    }
  }

  if (!flags.json_path.empty()) {
    nlohmann::json j;
    // Paths percent-encoded where they are not UTF-8, as in map.json (file_name_encoding.h).
    j["image0"] = {{"path", EncodeFileName(flags.image0)}, {"width", gray0.cols}, {"height", gray0.rows}};
    j["image1"] = {{"path", EncodeFileName(flags.image1)}, {"width", gray1.cols}, {"height", gray1.rows}};
    j["matcher"] = {{"type", matcher->name()}, {"options", nlohmann::json::parse(matcher->DescribeOptionsJson())}};
    j["verifier"] = {{"method", VerifierMethodName(verifier.method)},
                     {"threshold", verifier.threshold},
                     {"confidence", verifier.confidence},
                     {"seed", verifier.seed}};
    j["num_tentative"] = matches.size();
    j["num_verified"] = fundamental.num_inliers;
    j["verified"] = fundamental.success;
    j["similarity"] = similarity;
    if (fundamental.success) {
      j["F"] = nlohmann::json::array();
      for (int r = 0; r < 3; ++r) j["F"].push_back({fundamental.F(r, 0), fundamental.F(r, 1), fundamental.F(r, 2)});
    } else {
      j["F"] = nullptr;
    }
    auto& list = j["matches"] = nlohmann::json::array();
    for (size_t k = 0; k < matches.size(); ++k) {
      list.push_back({{"x0", matches.points0[k].x},
                      {"y0", matches.points0[k].y},
                      {"x1", matches.points1[k].x},
                      {"y1", matches.points1[k].y},
                      {"score", matches.scores.empty() ? 0.0f : matches.scores[k]},
                      {"inlier", fundamental.success && fundamental.inlier_mask[k] != 0}});
    }
    // x in image1 minus x in image0 at the scene both show; null without an estimate.
    j["heading_px"] = NumberOrNull(heading.px);
    j["heading_deg"] = NumberOrNull(heading.deg);  // null without --camera
    j["heading_method"] = HeadingMethodName(heading.method);
    j["heading_confidence"] = heading.confidence;
    j["heading_votes"] = heading.votes;
    j["heading_options"] = {{"window_px", flags.pair.heading.window_px},
                            {"window_dy_px", flags.pair.heading.window_dy_px},
                            {"min_votes", flags.pair.heading.min_votes},
                            {"min_verified", flags.pair.heading.min_verified}};
    j["time_s"] = {
        {"load", load_s}, {"extract", extract_s}, {"match", match_s}, {"verify", verify_s}, {"heading", heading_s}};
    WriteFileAtomically(flags.json_path, j.dump(1) + "\n");
  }
}

}  // namespace

void AddMatchCommand(CLI::App& app) {
  auto flags = std::make_shared<MatchFlags>();
  CLI::App* command = app.add_subcommand(
      "match",
      "Match one image pair: tentative matches (in original image pixels, with confidence), the verified "
      "subset and F, and the heading (x in image1 minus x in image0; degrees with --camera)");
  command->add_option("image0", flags->image0, "First image")->required();
  command->add_option("image1", flags->image1, "Second image")->required();
  command->add_option("--json", flags->json_path, "Also write every match, the inlier mask and F to this JSON file");
  command->add_flag("--list", flags->list, "Print every match: x0 y0 x1 y1 score inlier");
  flags->option_flags.AddOption(
      command, "--camera", flags->camera, "camera",
      "Intrinsics of both images (fx,fy,cx,cy[,k1,k2,p1,p2[,k3[,k4,k5,k6]]] or a calibration file): "
      "the heading also in degrees");
  AddOptionFlags(command, flags->pair, flags->option_flags);
  command->callback([flags] { flags->option_flags.Run([&] { RunMatch(*flags); }); });
}

}  // namespace vmap::cli
