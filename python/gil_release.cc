#include "gil_release.h"

#include <chrono>
#include <thread>

namespace py = pybind11;

namespace vmap::python {
namespace {

std::atomic<bool>& Exiting() {
  static std::atomic<bool> exiting{false};
  return exiting;
}

}  // namespace

std::atomic<int>& CallsWithoutGil() {
  static std::atomic<int> calls{0};
  return calls;
}

bool PythonIsExiting() { return Exiting(); }

void StopCallsWhenPythonExits() {
  py::module_::import("atexit").attr("register")(py::cpp_function([] {
    Exiting() = true;
    py::gil_scoped_release release;  // the calls take the GIL back as they return
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (CallsWithoutGil() > 0 && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }));
}

}  // namespace vmap::python
