// vmap.build_map, vmap.Matcher and vmap.match: the build pipeline and one pair's matching, their options as
// keywords (keyword_options.h).

#include <cmath>
#include <filesystem>
#include <memory>
#include <string>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <spdlog/spdlog.h>

#include "vmap/features/matcher_registry.h"
#include "vmap/mapping/pair_match.h"
#include "vmap/pipelines/build_pipeline.h"
#include "vmap/pipelines/match_pipeline.h"
#include "vmap/sources/image_frame.h"

#include "argument_errors.h"
#include "bindings.h"
#include "gil_release.h"
#include "keyword_options.h"
#include "map_objects.h"
#include "numpy_convert.h"
#include "python_results.h"

namespace py = pybind11;

namespace vmap::python {

namespace {

// The build pipeline's fields a call takes by keyword: not its positional arguments, nor the live runs' own.
const std::vector<const char*> kBuildMapSkipped = {"input", "output", "snapshot_every", "until_interrupted"};

std::shared_ptr<MapHandle> BuildMapFunction(const py::object& input, const py::object& output,
                                            const py::kwargs& kwargs) {
  BuildPipelineOptions options;
  KeywordOptions keywords("build_map");
  keywords.Add(options, kBuildMapSkipped);
  keywords.Parse(kwargs);
  options.input = TextArgument(input, "build_map(): input");
  options.output = TextArgument(output, "build_map(): output_dir");
  // The CLI's default folder beside the input is not taken from an empty string: the map would replace one the call
  // never named.
  if (options.output.empty()) {
    throw InputError("build_map(): output_dir '' names no folder; give the folder to write the map into");
  }
  // Ctrl-C between frames: KeyboardInterrupt, and the output left as it was.
  options.map.after_frame = RaisePendingSignals;
  BuildPipelineResult built;
  keywords.Run([&] {
    GilRelease release;
    built = RunBuildPipeline(options);
  });
  return ReadBuiltMapHandle(built.directory, built.map);
}

// A matcher and a verifier, created once and used for any number of pairs (a deep model's weights load once).
class PairMatcher {
 public:
  // `caller`: the Python name errors are given under ("Matcher", or "match" for vmap.match's matcher of one pair).
  explicit PairMatcher(const py::kwargs& kwargs, const char* caller = "Matcher") {
    KeywordOptions keywords(caller);
    keywords.Add(options_);
    keywords.Parse(kwargs);
    keywords.Run([&] {
      GilRelease release;
      options_.Check();
      matcher_ = CreateMatcher(options_.matcher);
    });
  }

  py::object Match(const py::object& image0, const py::object& image1) const {
    const ImageInput input0 = ImageView(image0, "image0"), input1 = ImageView(image1, "image1");
    PairMatch pair;
    {
      GilRelease release;
      const Frame frame0 = FrameFromImage(input0.image, 0, {}, "image0");
      const Frame frame1 = FrameFromImage(input1.image, 1, {}, "image1");
      pair = MatchPair(*matcher_, {frame0.gray, frame0.color}, {frame1.gray, frame1.color}, options_.verifier,
                       options_.heading);
    }
    const size_t n = pair.matches.size();
    const bool verified = pair.fundamental.success;
    py::array_t<float> matches({static_cast<py::ssize_t>(n), py::ssize_t{4}});
    py::array_t<float> scores(static_cast<py::ssize_t>(n));
    py::array_t<bool> inliers(static_cast<py::ssize_t>(n));
    for (size_t k = 0; k < n; ++k) {
      float* row = matches.mutable_data(k);
      row[0] = pair.matches.points0[k].x, row[1] = pair.matches.points0[k].y;
      row[2] = pair.matches.points1[k].x, row[3] = pair.matches.points1[k].y;
      scores.mutable_at(k) = pair.matches.scores.empty() ? std::nanf("") : pair.matches.scores[k];  // unscored
      inliers.mutable_at(k) = verified && pair.fundamental.inlier_mask[k] != 0;
    }
    // Named as `vmap match --json` names them; a field added there is one more line here.
    const HeadingOptions& heading_options = options_.heading;
    py::dict fields;
    fields["num_tentative"] = n;
    fields["num_verified"] = pair.fundamental.num_inliers;
    fields["verified"] = verified;
    fields["similarity"] = pair.similarity;
    fields["F"] = MatrixArray(pair.fundamental.F, verified);
    fields["matches"] = matches;
    fields["scores"] = scores;
    fields["inliers"] = inliers;
    const HeadingEstimate& heading = pair.heading;
    fields["heading_px"] = heading.valid() ? py::object(py::float_(heading.px)) : py::object(py::none());
    fields["heading_deg"] = py::none();  // vmap match gives it with --camera; the module takes no camera yet
    fields["heading_method"] = HeadingMethodName(heading.method);
    fields["heading_confidence"] = heading.confidence;
    fields["heading_votes"] = heading.votes;
    fields["heading_options"] = py::dict(
        py::arg("window_px") = heading_options.window_px, py::arg("window_dy_px") = heading_options.window_dy_px,
        py::arg("min_votes") = heading_options.min_votes, py::arg("min_verified") = heading_options.min_verified);
    fields["time_s"] = py::dict(py::arg("extract") = pair.extract_seconds, py::arg("match") = pair.match_seconds,
                                py::arg("verify") = pair.verify_seconds, py::arg("heading") = pair.heading_seconds);
    return Namespace(fields);
  }

  std::string name() const { return matcher_->name(); }
  py::object options() const { return py::module_::import("json").attr("loads")(matcher_->DescribeOptionsJson()); }

 private:
  PairMatchOptions options_;
  std::unique_ptr<Matcher> matcher_;
};

}  // namespace

void BindBuildAndMatch(py::module_& m) {
  static const std::string build_map_doc = KeywordDocstring<BuildPipelineOptions>(
      "Builds a map as `vmap build INPUT -o OUTPUT_DIR` does (the build pipeline), its options as keywords named as "
      "their fields (verifier_max_iterations=...) or as the CLI's flags (max_iters=...; vmap.build_map_options() "
      "lists them), and returns it (vmap.read_map). Ctrl-C abandons the build and leaves OUTPUT_DIR as it was.",
      kBuildMapSkipped);
  m.def("build_map", &BuildMapFunction, py::arg("input"), py::arg("output_dir"), build_map_doc.c_str());
  m.def(
      "build_map_options",
      [] {
        BuildPipelineOptions options;
        KeywordOptions keywords("build_map");
        keywords.Add(options, kBuildMapSkipped);
        return keywords.Keywords();
      },
      "The keywords vmap.build_map accepts.");

  static const std::string matcher_doc = KeywordDocstring<PairMatchOptions>(
      "A matcher and verifier as `vmap match` sets them up (the same keywords as vmap.match), for matching many "
      "pairs.");
  py::class_<PairMatcher>(m, "Matcher", matcher_doc.c_str())
      .def(py::init<const py::kwargs&>())
      .def(
          "match",
          [](const PairMatcher& self, const py::object& image0, const py::object& image1) {
            return Constructed(self, "Matcher").Match(image0, image1);
          },
          py::arg("image0"), py::arg("image1"), "Matches two uint8 images (HxW grey or HxWx3 BGR); see vmap.match.")
      .def_property_readonly("name", [](const PairMatcher& self) { return Constructed(self, "Matcher").name(); })
      .def_property_readonly("options", [](const PairMatcher& self) { return Constructed(self, "Matcher").options(); });
  m.def(
      "match",
      [](const py::object& image0, const py::object& image1, const py::kwargs& kwargs) {
        return PairMatcher(kwargs, "match").Match(image0, image1);
      },
      py::arg("image0"), py::arg("image1"),
      "Matches one pair as `vmap match` does (keywords: its options, e.g. matcher='orb', verifier_threshold=0.5; "
      "help(vmap.Matcher) lists them). Returns num_tentative, num_verified, verified, similarity, F (3x3 or None), "
      "matches (N x 4 float32: x0 y0 x1 y1), scores, inliers (N bools) and time_s.");
}

}  // namespace vmap::python
