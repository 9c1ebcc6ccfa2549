#pragma once
// The parts of the vmap module, each adding its functions and classes.

#include <string>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

namespace vmap::python {

// The C++ object of `self`, an instance of a bound class with a constructor. Class.__new__(Class) alone makes an
// object whose __init__ never ran: nothing stands behind it, and a method following it crashed the interpreter.
// Such an object (or another type's) is a TypeError instead.
template <typename T>
T& Constructed(pybind11::handle self, const char* name) {
  if (pybind11::isinstance<T>(self)) {
    auto* instance = reinterpret_cast<pybind11::detail::instance*>(self.ptr());
    const pybind11::detail::value_and_holder held =
        instance->get_value_and_holder(pybind11::detail::get_type_info(typeid(T)), /*throw_if_missing=*/false);
    if (held && held.holder_constructed()) return *held.value_ptr<T>();
  }
  throw pybind11::type_error(std::string("a vmap.") + name + " made with vmap." + name + "(...) was expected");
}

void BindMapObjects(pybind11::module_& module);     // map_objects.cc: Map, KeyImage, Link, read_map
void BindBuildAndMatch(pybind11::module_& module);  // build_and_match.cc: build_map, Matcher, match
void BindLocalization(pybind11::module_& module);   // localization.cc: Localizer, localize
void BindSimulation(pybind11::module_& module);     // simulation.cc: simulate

}  // namespace vmap::python
