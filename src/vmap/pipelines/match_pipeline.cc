#include "vmap/pipelines/match_pipeline.h"

#include <chrono>
#include <cmath>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "vmap/core/atomic_output.h"
#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/core/file_name_encoding.h"
#include "vmap/core/image_decode.h"
#include "vmap/core/image_header.h"
#include "vmap/core/stopwatch.h"
#include "vmap/pipelines/output_policies.h"
#include "vmap/sources/dataset_camera.h"
#include "vmap/sources/frame_source.h"

namespace vmap {

void PairMatchOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.VisitNested("heading", heading);
  visitor.VisitNested("", matcher);
  visitor.VisitNested("verifier", verifier, Nesting{false, {"max_samples_to_reject"}});
}

void PairMatchOptions::Check() const {
  CheckField("verifier", verifier);
  matcher.Check();
  CheckField("heading", heading);
}

void MatchPipelineOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit(OptionField{"image0", "image0", "First image"}.Positional(), image0);
  visitor.Visit(OptionField{"image1", "image1", "Second image"}.Positional(), image1);
  visitor.Section(kOutputSection);
  visitor.Visit(OptionField{"json", "--json", "Also write every match, the inlier mask and F to this JSON file"}
                    .HideDefault()
                    .NotRecorded(),
                json);
  visitor.Section(kInputSection);
  visitor.Visit(OptionField{"camera", "--camera",
                            "Intrinsics of both images (fx,fy,cx,cy[,k1,k2,p1,p2[,k3[,k4,k5,k6]]] or a calibration "
                            "file): the heading also in degrees"}
                    .HideDefault()
                    .NotRecorded(),
                camera);
  visitor.VisitNested("", pair);
}

void MatchPipelineOptions::Check() const { pair.Check(); }

namespace {

// The image file `path`, opened as a regular file (a FIFO or a device is refused before a decoder waits on it) and
// decoded from its bytes with `flags`; throws InputError naming it and why not.
cv::Mat ReadImage(const std::string& path, int flags) {
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
  const cv::Mat image = DecodeImageFile(*file, flags, kMaxFramePixels, &why_not);
  if (image.empty())
    throw InputError("image '" + path + "' " + why_not + "; check that it is an image of a usable size");
  return image;
}

// IMREAD_GRAYSCALE, not cvtColor: the decoder's conversion is what the reference implementations see.
cv::Mat ReadGray(const std::string& path) {
  cv::Mat gray = ReadImage(path, cv::IMREAD_GRAYSCALE);
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
  cv::Mat bgr = ReadImage(path, cv::IMREAD_COLOR);
  if (bgr.size() != size) throw InputError("image '" + path + "' changed while it was read; read it again");
  return bgr;
}

// The camera of `camera` for images of `size`; both images must have that size for a bearing to mean one thing.
std::optional<Camera> CameraOf(const std::string& camera, cv::Size size0, cv::Size size1) {
  if (camera.empty()) return std::nullopt;
  if (size0 != size1) {
    throw InputError("--camera needs both images at one size, but they are " + std::to_string(size0.width) + "x" +
                     std::to_string(size0.height) + " and " + std::to_string(size1.width) + "x" +
                     std::to_string(size1.height) + "; resize one, or leave out --camera for a heading in pixels");
  }
  return CameraForFrames(ParseCameraOption(camera), size0, size0);
}

nlohmann::json NumberOrNull(double value) { return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(); }

void WriteMatchJson(const MatchPipelineOptions& options, const MatchPipelineResult& result) {
  const VerifierOptions& verifier = options.pair.verifier;
  const HeadingOptions& heading_options = options.pair.heading;
  const TentativeMatches& matches = result.pair.matches;
  const FundamentalResult& fundamental = result.pair.fundamental;
  const HeadingEstimate& heading = result.pair.heading;
  nlohmann::json j;
  // Paths percent-encoded where they are not UTF-8, as in map.json (file_name_encoding.h).
  j["image0"] = {
      {"path", EncodeFileName(options.image0)}, {"width", result.size0.width}, {"height", result.size0.height}};
  j["image1"] = {
      {"path", EncodeFileName(options.image1)}, {"width", result.size1.width}, {"height", result.size1.height}};
  j["matcher"] = {{"type", result.matcher}, {"options", nlohmann::json::parse(result.matcher_options_json)}};
  j["verifier"] = {{"method", VerifierMethodName(verifier.method)},
                   {"threshold", verifier.threshold},
                   {"confidence", verifier.confidence},
                   {"seed", verifier.seed}};
  j["num_tentative"] = matches.size();
  j["num_verified"] = fundamental.num_inliers;
  j["verified"] = fundamental.success;
  j["similarity"] = result.pair.similarity;
  if (fundamental.success) {
    j["F"] = nlohmann::json::array();
    for (int r = 0; r < 3; ++r) j["F"].push_back({fundamental.F(r, 0), fundamental.F(r, 1), fundamental.F(r, 2)});
  } else {
    j["F"] = nullptr;
  }
  auto& list = j["matches"] = nlohmann::json::array();
  for (size_t k = 0; k < matches.size(); ++k) {
    list.push_back(
        {{"x0", matches.points0[k].x},
         {"y0", matches.points0[k].y},
         {"x1", matches.points1[k].x},
         {"y1", matches.points1[k].y},
         {"score", matches.scores.empty() ? nlohmann::json() : nlohmann::json(matches.scores[k])},  // null: unscored
         {"inlier", fundamental.success && fundamental.inlier_mask[k] != 0}});
  }
  // x in image1 minus x in image0 at the scene both show; null without an estimate.
  j["heading_px"] = NumberOrNull(heading.px);
  j["heading_deg"] = NumberOrNull(heading.deg);  // null without a camera
  j["heading_method"] = HeadingMethodName(heading.method);
  j["heading_confidence"] = heading.confidence;
  j["heading_votes"] = heading.votes;
  j["heading_options"] = {{"window_px", heading_options.window_px},
                          {"window_dy_px", heading_options.window_dy_px},
                          {"min_votes", heading_options.min_votes},
                          {"min_verified", heading_options.min_verified}};
  j["time_s"] = {{"load", result.load_seconds},
                 {"extract", result.pair.extract_seconds},
                 {"match", result.pair.match_seconds},
                 {"verify", result.pair.verify_seconds},
                 {"heading", result.pair.heading_seconds}};
  WriteFileAtomically(options.json, j.dump(1) + "\n");
}

}  // namespace

MatchPipelineResult RunMatchPipeline(const MatchPipelineOptions& options) {
  // 1. The options and the output.
  options.Check();
  CheckOutputs({{options.json, "json"}},
               {NamedInput(options.image0, "the input image"), NamedInput(options.image1, "the input image"),
                ExistingInputs({options.camera}, "the camera file"),
                ExistingInputs(options.pair.matcher.FilesRead(), "a file the matcher reads")});

  // 2. Both images, in grey.
  MatchPipelineResult result;
  const cv::Mat gray0 = ReadGray(options.image0), gray1 = ReadGray(options.image1);
  result.size0 = gray0.size();
  result.size1 = gray1.size();

  // 3. The camera.
  const std::optional<Camera> camera = CameraOf(options.camera, result.size0, result.size1);
  result.with_camera = camera.has_value();

  // 4. The matcher.
  const auto start = std::chrono::steady_clock::now();
  const std::unique_ptr<Matcher> matcher = CreateMatcher(options.pair.matcher);
  result.load_seconds = SecondsSince(start);
  result.matcher = matcher->name();
  result.matcher_options_json = matcher->DescribeOptionsJson();

  // 5. Extraction, matching, verification and heading: the library's, as the Python module's vmap.match runs them.
  // Decoded again in colour only for a matcher that reads colour: the grey image stays the decoder's.
  auto with_color = [&](const cv::Mat& gray, const std::string& path) {
    return matcher->reads_color() ? PairImage(gray, ReadColor(path, gray.size())) : PairImage(gray);
  };
  result.pair = MatchPair(*matcher, with_color(gray0, options.image0), with_color(gray1, options.image1),
                          options.pair.verifier, options.pair.heading, camera ? &*camera : nullptr);

  // 6. The JSON.
  if (!options.json.empty()) WriteMatchJson(options, result);
  return result;
}

}  // namespace vmap
