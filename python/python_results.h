#pragma once
// Results handed to Python: plain attribute objects (types.SimpleNamespace) made from a field list, so that a
// field the library adds to a record becomes an attribute with one line, or none (JSON records).

#include <nlohmann/json.hpp>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

namespace vmap::python {

// The JSON value as Python objects (dict, list, str, int, float, bool, None).
pybind11::object JsonToPython(const nlohmann::json& value);

// types.SimpleNamespace(**fields).
pybind11::object Namespace(const pybind11::dict& fields);

// Raises KeyboardInterrupt (or whatever a Python signal handler raised) as py::error_already_set into the C++
// work that polls it between frames. Called without the GIL, on the thread that runs Python's signal handlers.
void RaisePendingSignals();

// Notes Python's main thread for RaisePendingSignals; called once, at import, with the GIL held.
void RememberMainThread();

}  // namespace vmap::python
