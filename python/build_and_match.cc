// vmap.build_map, vmap.Matcher and vmap.match: `vmap build` and `vmap match` with the same options, as calls.

#include <filesystem>
#include <memory>
#include <string>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <spdlog/spdlog.h>

#include "vmap/cli/common_options.h"
#include "vmap/cli/map_options.h"
#include "vmap/core/atomic_output.h"
#include "vmap/features/matcher_registry.h"
#include "vmap/mapping/batch_build.h"
#include "vmap/mapping/map_builder.h"
#include "vmap/mapping/pair_match.h"
#include "vmap/sources/image_frame.h"

#include "bindings.h"
#include "keyword_options.h"
#include "map_objects.h"
#include "numpy_convert.h"
#include "python_results.h"

namespace py = pybind11;

namespace vmap::python {

namespace {

std::shared_ptr<MapHandle> BuildMapFunction(const std::string& input, const std::filesystem::path& output,
                                            const py::kwargs& kwargs) {
  // The options of `vmap build` (cli/build_command.cc), bound by the same calls.
  cli::SourceFlags source_flags;
  MatcherOptions matcher_options;
  cli::VerifierFlags verifier_flags;
  cli::KeyImageFlags key_image_flags;
  bool report = false;
  KeywordOptions keywords("build_map");
  cli::AddSourceOptions(keywords.command(), source_flags, keywords.option_flags());
  cli::AddMatcherOptions(keywords.command(), matcher_options, keywords.option_flags());
  cli::AddVerifierOptions(keywords.command(), verifier_flags, keywords.option_flags());
  cli::AddKeyImageOptions(keywords.command(), key_image_flags, keywords.option_flags());
  keywords.command()->add_flag("--report", report, "Also write report.html into the map directory");
  keywords.Parse(kwargs);
  keywords.Run([&] {
    py::gil_scoped_release release;
    const FrameSourceOptions source_options = source_flags.Resolve();
    MapBuilderOptions options = key_image_flags.Resolve(matcher_options.type);
    options.verifier = verifier_flags.Resolve();
    options.show_progress = spdlog::should_log(spdlog::level::info);
    options.Check();
    matcher_options.Check();
    options.after_frame = RaisePendingSignals;
    AtomicOutputDirectory directory(output, cli::MapOutputPolicy(input));
    const std::unique_ptr<Matcher> matcher = CreateMatcher(matcher_options);
    const std::unique_ptr<FrameSource> source = OpenFrameSource(input, source_options);
    const std::string options_json = cli::DescribeOptions(*matcher, options, source_options);
    BuildMap(*source, *matcher, options, directory.path(), options_json);
    cli::WriteReportIfAsked(report, directory.path());
    directory.Commit();
  });
  return ReadMapHandle(output);
}

// A matcher and a verifier, created once and used for any number of pairs (a deep model's weights load once).
class PairMatcher {
 public:
  explicit PairMatcher(const py::kwargs& kwargs) {
    // The options of `vmap match` (cli/match_command.cc): the matchers' and the verifier's without early stops.
    MatcherOptions matcher_options;
    cli::VerifierFlags verifier_flags;
    KeywordOptions keywords("Matcher");
    cli::AddMatcherOptions(keywords.command(), matcher_options, keywords.option_flags());
    cli::AddVerifierOptions(keywords.command(), verifier_flags, keywords.option_flags(), /*with_early_stop=*/false);
    cli::AddHeadingOptions(keywords.command(), heading_, keywords.option_flags());
    keywords.Parse(kwargs);
    keywords.Run([&] {
      py::gil_scoped_release release;
      verifier_ = verifier_flags.Resolve();
      matcher_options.Check();
      CheckField("heading", heading_);
      matcher_ = CreateMatcher(matcher_options);
    });
  }

  py::object Match(const py::object& image0, const py::object& image1) const {
    const ImageInput input0 = ImageView(image0, "image0"), input1 = ImageView(image1, "image1");
    PairMatch pair;
    {
      py::gil_scoped_release release;
      const Frame frame0 = FrameFromImage(input0.image, 0, {}, "image0");
      const Frame frame1 = FrameFromImage(input1.image, 1, {}, "image1");
      pair = MatchPair(*matcher_, {frame0.gray, frame0.color}, {frame1.gray, frame1.color}, verifier_, heading_);
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
      scores.mutable_at(k) = pair.matches.scores.empty() ? 0.0f : pair.matches.scores[k];
      inliers.mutable_at(k) = verified && pair.fundamental.inlier_mask[k] != 0;
    }
    // Named as `vmap match --json` names them; a field added there is one more line here.
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
    fields["heading_options"] =
        py::dict(py::arg("window_px") = heading_.window_px, py::arg("window_dy_px") = heading_.window_dy_px,
                 py::arg("min_votes") = heading_.min_votes, py::arg("min_verified") = heading_.min_verified);
    fields["time_s"] = py::dict(py::arg("extract") = pair.extract_seconds, py::arg("match") = pair.match_seconds,
                                py::arg("verify") = pair.verify_seconds, py::arg("heading") = pair.heading_seconds);
    return Namespace(fields);
  }

  std::string name() const { return matcher_->name(); }
  py::object options() const { return py::module_::import("json").attr("loads")(matcher_->DescribeOptionsJson()); }

 private:
  VerifierOptions verifier_;
  HeadingOptions heading_;
  std::unique_ptr<Matcher> matcher_;
};

}  // namespace

void BindBuildAndMatch(py::module_& m) {
  m.def("build_map", &BuildMapFunction, py::arg("input"), py::arg("output_dir"),
        "Builds a map as `vmap build INPUT -o OUTPUT_DIR` does, with its options as keywords (--max-iters: "
        "max_iters=...; vmap.build_map_options() lists them), and returns it (vmap.read_map). Ctrl-C abandons "
        "the build and leaves OUTPUT_DIR as it was.");
  m.def(
      "build_map_options",
      [] {
        cli::SourceFlags source;
        MatcherOptions matcher;
        cli::VerifierFlags verifier;
        cli::KeyImageFlags key_images;
        bool report = false;
        KeywordOptions keywords("build_map");
        cli::AddSourceOptions(keywords.command(), source, keywords.option_flags());
        cli::AddMatcherOptions(keywords.command(), matcher, keywords.option_flags());
        cli::AddVerifierOptions(keywords.command(), verifier, keywords.option_flags());
        cli::AddKeyImageOptions(keywords.command(), key_images, keywords.option_flags());
        keywords.command()->add_flag("--report", report, "");
        return keywords.Keywords();
      },
      "The keywords vmap.build_map accepts.");

  py::class_<PairMatcher>(m, "Matcher",
                          "A matcher and verifier as `vmap match` sets them up (the same keywords as vmap.match), "
                          "for matching many pairs.")
      .def(py::init<const py::kwargs&>())
      .def("match", &PairMatcher::Match, py::arg("image0"), py::arg("image1"),
           "Matches two uint8 images (HxW grey or HxWx3 BGR); see vmap.match.")
      .def_property_readonly("name", &PairMatcher::name)
      .def_property_readonly("options", &PairMatcher::options);
  m.def(
      "match",
      [](const py::object& image0, const py::object& image1, const py::kwargs& kwargs) {
        return PairMatcher(kwargs).Match(image0, image1);
      },
      py::arg("image0"), py::arg("image1"),
      "Matches one pair as `vmap match` does (keywords: its options, e.g. matcher='orb', threshold=0.5). "
      "Returns num_tentative, num_verified, verified, similarity, F (3x3 or None), matches (N x 4 float32: x0 y0 "
      "x1 y1), scores, inliers (N bools) and time_s.");
}

}  // namespace vmap::python
