#pragma once
// The errors of the module's argument conversion: every argument is converted with its type checked, so that
// no Python value reaches the library unchecked (a wrong type is an exception, never a crash).

#include <string>

#include <pybind11/pybind11.h>

#include "vmap/core/error.h"

namespace vmap::python {

// An argument of the wrong type: vmap.ArgumentTypeError, both a TypeError (the wrong type, as Python says it)
// and a vmap.Error (a ValueError: scripts that catch vmap's errors catch it too).
class ArgumentTypeError : public InputError {
 public:
  using InputError::InputError;
};

// "str", "list", ...: the name of the value's type, for messages.
std::string TypeName(const pybind11::handle& value);

// The value as a C++ number or text, its type checked (GIL held). `what` names the argument in messages
// ("timestamp", "build_map(): stride").
// int: a Python int or a numpy integer, not a bool; out of int's range: vmap.Error.
int IntArgument(const pybind11::handle& value, const std::string& what);
// float: a Python float or int, or a numpy number, not a bool; an int too large for a double: vmap.Error.
double FloatArgument(const pybind11::handle& value, const std::string& what);
// bool: True or False (or a numpy bool).
bool BoolArgument(const pybind11::handle& value, const std::string& what);
// str: a str, bytes or os.PathLike, as the file system's bytes (os.fsencode); no NUL character.
std::string TextArgument(const pybind11::handle& value, const std::string& what);

}  // namespace vmap::python
