#include "argument_errors.h"

#include <climits>
#include <cmath>

namespace py = pybind11;

namespace vmap::python {

namespace {

bool IsBool(const py::handle& value) {
  if (PyBool_Check(value.ptr())) return true;
  static const py::object numpy_bool = py::module_::import("numpy").attr("bool_");
  return py::isinstance(value, numpy_bool);
}

[[noreturn]] void WrongType(const py::handle& value, const std::string& what, const char* expected) {
  throw ArgumentTypeError(what + " takes " + expected + ", not " + TypeName(value));
}

}  // namespace

std::string TypeName(const py::handle& value) {
  return py::str(py::type::handle_of(value).attr("__name__")).cast<std::string>();
}

int IntArgument(const py::handle& value, const std::string& what) {
  if (IsBool(value) || !PyIndex_Check(value.ptr())) WrongType(value, what, "an int");
  const py::object index = py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()));
  if (!index) throw py::error_already_set();
  int overflow = 0;
  const long long number = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
  if (number == -1 && PyErr_Occurred()) throw py::error_already_set();
  if (overflow != 0 || number < INT_MIN || number > INT_MAX) {
    throw InputError(what + " is out of range: an int from " + std::to_string(INT_MIN) + " to " +
                     std::to_string(INT_MAX));
  }
  return static_cast<int>(number);
}

double FloatArgument(const py::handle& value, const std::string& what) {
  const bool number = PyFloat_Check(value.ptr()) || PyIndex_Check(value.ptr()) || py::hasattr(value, "__float__");
  if (IsBool(value) || !number || PyUnicode_Check(value.ptr()) || PyBytes_Check(value.ptr())) {
    WrongType(value, what, "a number");
  }
  const double result = PyFloat_AsDouble(value.ptr());
  if (result == -1.0 && PyErr_Occurred()) {
    if (PyErr_ExceptionMatches(PyExc_OverflowError)) {
      PyErr_Clear();
      throw InputError(what + " is out of range: too large for a float");
    }
    throw py::error_already_set();
  }
  return result;
}

bool BoolArgument(const py::handle& value, const std::string& what) {
  if (!IsBool(value)) WrongType(value, what, "True or False");
  return PyObject_IsTrue(value.ptr()) == 1;
}

std::string TextArgument(const py::handle& value, const std::string& what) {
  const bool text = PyUnicode_Check(value.ptr()) || PyBytes_Check(value.ptr()) || py::hasattr(value, "__fspath__");
  if (!text) WrongType(value, what, "a str (or a path)");
  // The file system's bytes, as a command line would give them (undecodable names round-trip).
  const py::bytes bytes = py::module_::import("os").attr("fsencode")(value);
  std::string result = bytes;
  if (result.find('\0') != std::string::npos) throw InputError(what + " contains a NUL character");
  return result;
}

}  // namespace vmap::python
