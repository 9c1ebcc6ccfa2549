#include "python_results.h"

#include "gil_release.h"

namespace py = pybind11;

namespace vmap::python {

py::object JsonToPython(const nlohmann::json& value) {
  switch (value.type()) {
    case nlohmann::json::value_t::null:
      return py::none();
    case nlohmann::json::value_t::boolean:
      return py::bool_(value.get<bool>());
    case nlohmann::json::value_t::number_integer:
      return py::int_(value.get<long long>());
    case nlohmann::json::value_t::number_unsigned:
      return py::int_(value.get<unsigned long long>());
    case nlohmann::json::value_t::number_float:
      return py::float_(value.get<double>());
    case nlohmann::json::value_t::string:
      return py::str(value.get_ref<const std::string&>());
    case nlohmann::json::value_t::array: {
      py::list list;
      for (const auto& item : value) list.append(JsonToPython(item));
      return std::move(list);
    }
    case nlohmann::json::value_t::object: {
      py::dict dict;
      for (const auto& [key, item] : value.items()) dict[py::str(key)] = JsonToPython(item);
      return std::move(dict);
    }
    default:
      return py::none();  // binary and discarded values never occur in vmap's records
  }
}

py::object Namespace(const py::dict& fields) { return py::module_::import("types").attr("SimpleNamespace")(**fields); }

namespace {

// Python's main thread, the only one that runs signal handlers: known at import (threading.main_thread()).
unsigned long MainThread() {
  static const unsigned long main_thread = [] {
    py::gil_scoped_acquire acquire;
    return py::module_::import("threading").attr("main_thread")().attr("ident").cast<unsigned long>();
  }();
  return main_thread;
}

}  // namespace

void RememberMainThread() { MainThread(); }

void RaisePendingSignals() {
  if (PythonIsExiting()) {
    // SystemExit, which a thread ends with silently. The GIL is free to take: the exit waits for the calls in C++
    // (gil_release.h) before the interpreter is finalized.
    py::gil_scoped_acquire acquire;
    PyErr_SetNone(PyExc_SystemExit);
    throw py::error_already_set();
  }
  // Another thread has no signal to raise, and takes no GIL here: while the interpreter exits, a daemon thread
  // taking it from here was ended by CPython in a way that aborted the process.
  if (PyThread_get_thread_ident() != MainThread()) return;
  py::gil_scoped_acquire acquire;
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
}

}  // namespace vmap::python
