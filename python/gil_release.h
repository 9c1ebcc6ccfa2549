#pragma once
// The GIL released around C++ work, so that other Python threads run meanwhile; and that work stopped when Python
// exits while a daemon thread is in it.

#include <Python.h>

#include <atomic>

#include <pybind11/pybind11.h>

namespace vmap::python {

// The calls in C++ work with the GIL released, now.
std::atomic<int>& CallsWithoutGil();

// As pybind11's gil_scoped_release, except that taking the GIL back may end the thread. When the interpreter exits
// while a daemon thread is in vmap, CPython ends that thread as it takes the GIL back, by pthread_exit, which
// unwinds the thread's stack; from pybind11's guard, whose destructor is noexcept, that unwinding became
// std::terminate, and the program's normal exit "Aborted" (a GUI's or a rospy node's worker thread). Here it
// passes, and the thread ends quietly as Python ends its daemon threads.
class GilRelease {
 public:
  GilRelease() : state_(PyEval_SaveThread()) { ++CallsWithoutGil(); }
  ~GilRelease() noexcept(false) {
    --CallsWithoutGil();
    PyEval_RestoreThread(state_);
  }
  GilRelease(const GilRelease&) = delete;
  GilRelease& operator=(const GilRelease&) = delete;

 private:
  PyThreadState* state_;
};

// Whether Python is exiting: the work polling RaisePendingSignals (python_results.h) then stops at its next frame.
bool PythonIsExiting();

// Registers, at import, the atexit handler that sets PythonIsExiting and waits (10 s at most) for the calls in
// C++ to return: a daemon thread's build would otherwise still run while the process exits (its static objects
// destroyed under it: an abort), and would leave its temporary output behind.
void StopCallsWhenPythonExits();

}  // namespace vmap::python
