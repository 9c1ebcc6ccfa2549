#pragma once
// The parts of the vmap module, each adding its functions and classes.

#include <string>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

namespace vmap::python {

// `object`, the C++ side of a bound class's instance, once its __init__ ran. Class.__new__(Class) alone makes an
// instance that pybind11 gives uninitialised memory when a method is called on it (a crash); such an object was
// never registered as an instance, which is what tells it apart. A TypeError instead.
template <typename T>
T& Constructed(T& object, const char* name) {
  if (!pybind11::detail::get_object_handle(&object, pybind11::detail::get_type_info(typeid(T)))) {
    throw pybind11::type_error(std::string("a vmap.") + name + " made with vmap." + name + "(...) was expected");
  }
  return object;
}

void BindMapObjects(pybind11::module_& module);     // map_objects.cc: Map, KeyImage, Link, read_map
void BindBuildAndMatch(pybind11::module_& module);  // build_and_match.cc: build_map, Matcher, match
void BindLocalization(pybind11::module_& module);   // localization.cc: Localizer, localize
void BindSimulation(pybind11::module_& module);     // simulation.cc: simulate

}  // namespace vmap::python
