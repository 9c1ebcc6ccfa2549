// vmap.Localizer and vmap.localize: `vmap localize` with the same options, one frame at a time or a sequence.

#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <spdlog/spdlog.h>

#include "vmap/cli/common_options.h"
#include "vmap/cli/localize_options.h"
#include "vmap/localization/localization_map.h"
#include "vmap/localization/localization_output.h"
#include "vmap/localization/localize_sequence.h"
#include "vmap/localization/route.h"
#include "vmap/map/map_io.h"
#include "vmap/sources/image_frame.h"

#include "bindings.h"
#include "keyword_options.h"
#include "map_objects.h"
#include "numpy_convert.h"
#include "python_results.h"

namespace py = pybind11;

namespace vmap::python {

namespace {

// A result as vmap localize's JSON lists a frame (the CSV's columns), with F, R and t as numpy arrays.
py::object ResultObject(const VisualMap& map, const LocalizationResult& result) {
  nlohmann::json record = LocalizationFrameJson(map, result);
  py::dict fields;
  for (const auto& [key, value] : record.items()) {
    if (key == "pose") continue;
    fields[py::str(key)] = JsonToPython(value);
  }
  fields["F"] = MatrixArray(result.to_next.F, result.to_next.matched);
  const nlohmann::json& pose = record["pose"];
  if (pose.is_null()) {
    fields["R"] = py::none(), fields["t"] = py::none();
  } else {
    cv::Matx33d R;
    cv::Vec3d t;
    for (int i = 0; i < 9; ++i) R(i / 3, i % 3) = pose["R"][i].get<double>();
    for (int i = 0; i < 3; ++i) t[i] = pose["t"][i].get<double>();
    fields["R"] = MatrixArray(R), fields["t"] = VectorArray(t);
  }
  return Namespace(fields);
}

// The map opened for localization and a Localizer on it, for frames given one at a time.
class FrameLocalizer {
 public:
  FrameLocalizer(const py::object& map, const py::kwargs& kwargs) {
    cli::LocalizerFlags flags;
    KeywordOptions keywords("Localizer");
    cli::AddLocalizerOptions(keywords.command(), flags, keywords.option_flags());
    keywords.Parse(kwargs);
    const std::filesystem::path directory = MapDirectory(map);
    keywords.Run([&] {
      py::gil_scoped_release release;
      LocalizerOptions options = flags.localizer;
      options.Check();
      cli::CheckLocalizerFlags(flags);
      KeyImageStoreOptions store_options;
      store_options.use_cache = flags.cache;
      store_options.thumbnail_width = options.ranking.thumbnail_width;
      opened_ = std::make_unique<LocalizationMap>(OpenLocalizationMap(directory, store_options));
      options.route = cli::RouteOf(opened_->map, flags, options.route);
      // Frames are brought to the map's size, so the map's camera applies.
      options = FollowMap(*opened_, options, QueryResize(opened_->map, ""));
      options.Check();
      localizer_ = std::make_unique<Localizer>(opened_->map, opened_->keys, *opened_->matcher, options);
    });
  }

  py::object Localize(const py::object& image, const py::object& timestamp) {
    const ImageInput input = ImageView(image, "image");
    LocalizationResult result;
    {
      py::gil_scoped_release release;
      Frame frame = FrameFromImage(input.image, frames_, opened_->map.input.frame_size, "image");
      if (!timestamp.is_none()) frame.timestamp = timestamp.cast<double>();
      const auto features = opened_->matcher->ExtractFrame(frame.gray, frame.color);
      result = localizer_->Localize(frame, *features);
    }
    ++frames_;
    return ResultObject(opened_->map, result);
  }

  void Reset() { localizer_->Reset(); }

 private:
  std::unique_ptr<LocalizationMap> opened_;
  std::unique_ptr<Localizer> localizer_;
  int frames_ = 0;  // frames localized: the next one's index
};

py::list LocalizeFunction(const py::object& map, const std::string& query, const py::kwargs& kwargs) {
  // The options of `vmap localize` (cli/localize_command.cc), bound by the same calls.
  cli::SourceFlags source_flags;
  cli::LocalizerFlags flags;
  KeywordOptions keywords("localize");
  cli::AddSourceOptions(keywords.command(), source_flags, keywords.option_flags());
  cli::AddLocalizerOptions(keywords.command(), flags, keywords.option_flags());
  keywords.Parse(kwargs);
  const std::filesystem::path directory = MapDirectory(map);
  std::unique_ptr<LocalizationMap> opened;
  std::vector<LocalizationResult> results;
  keywords.Run([&] {
    py::gil_scoped_release release;
    cli::LocalizationSetup setup = cli::SetUpLocalization(flags, source_flags.Resolve(), directory, query);
    opened = std::move(setup.opened);
    Localizer localizer(opened->map, opened->keys, *opened->matcher, setup.options);
    LocalizeSequence(*setup.source, *opened->matcher, localizer, setup.run_options,
                     [&](const Frame&, const LocalizationResult& result) {
                       results.push_back(result);
                       RaisePendingSignals();
                     });
  });
  py::list list;
  for (const LocalizationResult& result : results) list.append(ResultObject(opened->map, result));
  return list;
}

}  // namespace

void BindLocalization(py::module_& m) {
  py::class_<FrameLocalizer>(m, "Localizer",
                             "Localizes frames one at a time against a map (a vmap.Map or its directory), with the "
                             "options of `vmap localize` as keywords (min_verified=..., ranking=..., ...).")
      .def(py::init<const py::object&, const py::kwargs&>(), py::arg("map"))
      .def("localize", &FrameLocalizer::Localize, py::arg("image"), py::arg("timestamp") = py::none(),
           "Localizes the next frame (uint8 HxW grey or HxWx3 BGR; brought to the map's frame size). Returns an "
           "object whose attributes are the columns of `vmap localize --csv` (status, key, next_key, similarity, "
           "heading_px, ...), with F, R and t as numpy arrays (None when unknown).")
      .def("reset", &FrameLocalizer::Reset, "Forgets the estimate: the next frame is relocalized.");
  m.def("localize", &LocalizeFunction, py::arg("map"), py::arg("input"),
        "Localizes every frame of INPUT (video, image folder, dataset or one image) as `vmap localize MAP INPUT` "
        "does, with its options as keywords; returns one result per frame (see Localizer.localize).");
}

}  // namespace vmap::python
