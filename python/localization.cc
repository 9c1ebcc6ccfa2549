// vmap.Localizer and vmap.localize: the localization pipeline, one frame at a time (its session) or over a whole
// query, its options as keywords (keyword_options.h).

#include <cmath>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "vmap/localization/localization_output.h"
#include "vmap/pipelines/localize_pipeline.h"

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

// A result as vmap localize's JSON lists a frame (the CSV's columns), with F, R and t as numpy arrays.
py::object ResultObject(const VisualMap& map, const LocalizationResult& result) {
  // A map with experiences adds the columns that say whether each comparison was with a view (F and the counts are
  // then against it), as the CLI's JSON does.
  nlohmann::json record = LocalizationFrameJson(map, result, !map.experiences.empty());
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

// The robot's odometry pose at a frame, (x, y, yaw) in metres and radians, or None.
std::optional<OdometrySample> OdometryArgument(const py::object& odometry, std::optional<double> timestamp) {
  if (odometry.is_none()) return std::nullopt;
  const auto why =
      "odometry must be (x, y, yaw): the robot's odometry pose at the frame in metres and radians, or None";
  if (!py::isinstance<py::sequence>(odometry) || py::isinstance<py::str>(odometry) ||
      py::isinstance<py::bytes>(odometry) || py::len(odometry) != 3) {
    throw InputError(why);
  }
  const py::sequence values = odometry.cast<py::sequence>();
  OdometrySample sample;
  sample.timestamp = timestamp.value_or(0.0);
  sample.x = FloatArgument(values[0], "odometry x");
  sample.y = FloatArgument(values[1], "odometry y");
  sample.yaw = FloatArgument(values[2], "odometry yaw");
  if (!(std::isfinite(sample.x) && std::isfinite(sample.y) && std::isfinite(sample.yaw))) {
    throw InputError(std::string(why) + "; a value is not finite");
  }
  return sample;
}

// The localization session of a map, for frames given one at a time.
class FrameLocalizer {
 public:
  FrameLocalizer(const py::object& map, const py::kwargs& kwargs) {
    LocalizePipelineOptions options;
    KeywordOptions keywords("Localizer");
    keywords.Add(options.session);
    keywords.Parse(kwargs);
    options.map = MapDirectory(map).string();
    keywords.Run([&] {
      GilRelease release;
      options.session.CheckGiven(keywords.Given());
      session_ = std::make_unique<LocalizationSession>(options);
    });
  }

  py::object Localize(const py::object& image, const py::object& timestamp, const py::object& odometry) {
    const ImageInput input = ImageView(image, "image");
    std::optional<double> seconds;
    if (!timestamp.is_none()) {
      seconds = FloatArgument(timestamp, "timestamp");
      if (!std::isfinite(*seconds)) throw InputError("timestamp is not finite; give the frame's time in seconds");
      // A negative time is the library's "none" (a frame without one), which would drop it without a word.
      if (*seconds < 0.0) {
        throw InputError(
            fmt::format("timestamp {} is negative; give the frame's time in seconds from 0 (as ROS stamps "
                        "are), or None",
                        *seconds));
      }
    }
    const std::optional<OdometrySample> pose = OdometryArgument(odometry, seconds);
    LocalizationResult result;
    {
      // Python threads may share one Localizer: its frames are one run, so they take turns (the session is not
      // thread-safe: two frames at once deadlocked in its speculative comparisons). The GIL is released first, so
      // that the thread waiting here holds nothing the one localizing needs.
      GilRelease release;
      const std::lock_guard<std::mutex> lock(mutex_);
      result = session_->Localize(input.image, seconds, pose);
    }
    return ResultObject(session_->map(), result);
  }

  void Reset() {
    GilRelease release;
    const std::lock_guard<std::mutex> lock(mutex_);
    session_->Reset();
  }

 private:
  std::unique_ptr<LocalizationSession> session_;
  std::mutex mutex_;  // one frame (or reset) at a time
};

// The localize pipeline's fields vmap.localize takes by keyword: not its positional arguments, nor the CLI's outputs.
// The odometry's columns are not a result's, but its poses pace the belief (with the teach odometry).
const std::vector<const char*> kLocalizeSkipped = {"map", "query", "csv", "json", "report"};

py::list LocalizeFunction(const py::object& map, const py::object& query, const py::kwargs& kwargs) {
  LocalizePipelineOptions options;
  KeywordOptions keywords("localize");
  keywords.Add(options, kLocalizeSkipped);
  keywords.Parse(kwargs);
  options.map = MapDirectory(map).string();
  options.query = TextArgument(query, "localize(): input");
  LocalizePipelineResult run;
  keywords.Run([&] {
    GilRelease release;
    options.session.CheckGiven(keywords.Given());
    run = RunLocalizePipeline(options, [](const Frame&, const LocalizationResult&) { RaisePendingSignals(); });
  });
  py::list list;
  for (const LocalizationResult& result : run.run.frames) list.append(ResultObject(run.map, result));
  return list;
}

}  // namespace

void BindLocalization(py::module_& m) {
  static const std::string localizer_doc = KeywordDocstring<LocalizationSessionOptions>(
      "Localizes frames one at a time against a map (a vmap.Map or its directory), with the options of `vmap "
      "localize` as keywords (candidates=..., ranking=..., ...).");
  py::class_<FrameLocalizer>(m, "Localizer", localizer_doc.c_str())
      .def(py::init<const py::object&, const py::kwargs&>(), py::arg("map"))
      .def(
          "localize",
          [](FrameLocalizer& self, const py::object& image, const py::object& timestamp, const py::object& odometry) {
            return Constructed(self, "Localizer").Localize(image, timestamp, odometry);
          },
          py::arg("image"), py::arg("timestamp") = py::none(), py::arg("odometry") = py::none(),
          "Localizes the next frame (uint8 HxW grey or HxWx3 BGR; brought to the map's frame size; timestamp in "
          "seconds or None; odometry the robot's pose (x, y, yaw) in metres and radians at the frame, or None: with "
          "the teach odometry, teach_odometry=..., the belief moves by the distance driven). Returns an object whose "
          "attributes are the columns of `vmap localize --csv` (status, "
          "key, next_key, similarity, heading_px, ...), with F, R and t as numpy arrays (None when unknown).")
      .def(
          "reset", [](FrameLocalizer& self) { Constructed(self, "Localizer").Reset(); },
          "Forgets the estimate: the next frame is relocalized.");
  static const std::string localize_doc = KeywordDocstring<LocalizePipelineOptions>(
      "Localizes every frame of INPUT (video, image folder, dataset or one image) as `vmap localize MAP INPUT` does, "
      "with its options as keywords; returns one result per frame (see Localizer.localize).",
      kLocalizeSkipped);
  m.def("localize", &LocalizeFunction, py::arg("map"), py::arg("input"), localize_doc.c_str());
}

}  // namespace vmap::python
