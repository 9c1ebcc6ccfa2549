// vmap.simulate: the simulate pipeline (a route taught in a simulated corridor and repeated from random offsets,
// vmap's localizer and route controller in the loop), its options as keywords (keyword_options.h).

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "vmap/pipelines/simulate_pipeline.h"
#include "vmap/simulation/simulation_output.h"

#include "bindings.h"
#include "gil_release.h"
#include "keyword_options.h"
#include "python_results.h"

namespace py = pybind11;

namespace vmap::python {

namespace {

py::object SimulateFunction(const py::kwargs& kwargs) {
  SimulatePipelineOptions options;
  KeywordOptions keywords("simulate");
  keywords.Add(options);
  keywords.Parse(kwargs);
  // Ctrl-C between frames: KeyboardInterrupt, and nothing written.
  options.after_frame = RaisePendingSignals;
  nlohmann::json record;
  keywords.Run([&] {
    GilRelease release;
    const SimulatePipelineResult result = RunSimulatePipeline(options);
    record = SimulationJson(result.simulation, options.simulation);
  });
  return JsonToPython(record);
}

}  // namespace

void BindSimulation(py::module_& m) {
  static const std::string doc = KeywordDocstring<SimulatePipelineOptions>(
      "Teaches a route in a simulated corridor and repeats it from random offsets with vmap's localizer and route "
      "controller in the loop, as `vmap simulate` does, with its options as keywords (route='turn', trials=10, "
      "law='tracker', matcher='orb', json=..., report=..., map=...). Returns the run as `vmap simulate --json` "
      "writes it: a dict with options, route, teach, summary and every trial with its samples.");
  m.def("simulate", &SimulateFunction, doc.c_str());
}

}  // namespace vmap::python
