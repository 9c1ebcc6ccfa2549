#pragma once
// The parts of the vmap module, each adding its functions and classes.

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

namespace vmap::python {

void BindMapObjects(pybind11::module_& module);     // map_objects.cc: Map, KeyImage, Link, read_map
void BindBuildAndMatch(pybind11::module_& module);  // build_and_match.cc: build_map, Matcher, match
void BindLocalization(pybind11::module_& module);   // localization.cc: Localizer, localize
void BindSimulation(pybind11::module_& module);     // simulation.cc: simulate

}  // namespace vmap::python
