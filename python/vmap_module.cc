// The `vmap` Python module: vmap's maps as numpy arrays, its matchers and localizer as functions (docs/python.md).
// A thin layer: every call runs a pipeline (src/vmap/pipelines/) or a stage of the library, its options structs
// bound by field (keyword_options.h).

#include <string>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "vmap/core/error.h"
#include "vmap/core/logging.h"
#include "vmap/core/runtime.h"
#include "vmap/core/temporary_name.h"
#include "vmap/features/matcher_registry.h"

#include "argument_errors.h"
#include "bindings.h"
#include "gil_release.h"
#include "python_results.h"

namespace py = pybind11;

PYBIND11_MODULE(vmap, m) {
  m.doc() = "vmap: visual maps for teach-and-repeat navigation (key images linked by fundamental matrices)";
  m.attr("__version__") = VMAP_VERSION;

  // vmap's errors (bad input, bad options) carry the library's message, options named by keyword; a ValueError,
  // so generic handlers catch them. An argument of the wrong type is also a TypeError.
  static py::exception<vmap::InputError> error(m, "Error", PyExc_ValueError);
  static py::object argument_type_error = py::reinterpret_steal<py::object>(PyErr_NewExceptionWithDoc(
      "vmap.ArgumentTypeError", "An argument of the wrong type: a TypeError, and a vmap.Error.",
      py::make_tuple(error, py::handle(PyExc_TypeError)).ptr(), nullptr));
  m.attr("ArgumentTypeError") = argument_type_error;
  py::register_exception_translator([](std::exception_ptr pending) {
    try {
      if (pending) std::rethrow_exception(pending);
    } catch (const vmap::python::ArgumentTypeError& e) {
      PyErr_SetString(argument_type_error.ptr(), e.what());
    } catch (const vmap::InputError& e) {
      PyErr_SetString(error.ptr(), vmap::NameOutputsNotTemporaries(e.what()).c_str());
    }
  });

  vmap::python::RememberMainThread();
  vmap::python::StopCallsWhenPythonExits();

  // vmap's log (spdlog's "vmap" logger) to stderr at info, as the CLI; vmap.set_log_level changes it.
  vmap::ConfigureLogging("info");
  m.def(
      "set_log_level",
      [](const py::object& level) {
        vmap::ConfigureLogging(vmap::python::TextArgument(level, "set_log_level(): level"));
      },
      py::arg("level"),
      "vmap's log: 'quiet' (warnings and errors; no progress line), 'info' (the default) or 'debug'.");
  m.def(
      "initialize_runtime",
      [](const py::object& opencv_threads, const py::object& keep_freed_memory, const py::object& quiet_ffmpeg) {
        // Type-checked as every argument of the module is; None keeps the default.
        using vmap::python::BoolArgument;
        using vmap::python::IntArgument;
        vmap::RuntimeOptions options;
        if (!opencv_threads.is_none()) options.opencv_threads = IntArgument(opencv_threads, "opencv_threads");
        if (!keep_freed_memory.is_none()) {
          options.keep_freed_memory = BoolArgument(keep_freed_memory, "keep_freed_memory");
        }
        if (!quiet_ffmpeg.is_none()) options.quiet_ffmpeg = BoolArgument(quiet_ffmpeg, "quiet_ffmpeg");
        options.handle_interrupts = false;  // Python handles signals
        options.Check();
        vmap::InitializeRuntime(options);
      },
      py::kw_only(), py::arg("opencv_threads") = 1, py::arg("keep_freed_memory") = true, py::arg("quiet_ffmpeg") = true,
      "Opt-in: the process-wide settings the vmap CLI makes at start (core/runtime.h: OpenCV's threads, malloc "
      "keeping freed memory, FFmpeg's log), for timings equal to the CLI's. Python keeps its own signal handling.");
  m.def(
      "matchers",
      [] {
        std::vector<std::string> names;
        for (const auto& model : vmap::MatcherModels()) names.push_back(model.name);
        return names;
      },
      "The registered matcher models (matcher=...).");

  vmap::python::BindMapObjects(m);
  vmap::python::BindBuildAndMatch(m);
  vmap::python::BindLocalization(m);
  vmap::python::BindSimulation(m);
}
