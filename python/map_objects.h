#pragma once
// vmap.Map, vmap.KeyImage and vmap.Link: a map directory as ReadMap reads it, its key images decoded only when
// asked for (a long map's images would not fit in memory at once).

#include <filesystem>
#include <memory>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "vmap/map/visual_map.h"
#include "vmap/mapping/recorded_options.h"

namespace vmap::python {

struct MapHandle {
  std::filesystem::path directory;
  VisualMap map;
  RecordedOptions options;  // what the map records of the options that shaped it, typed
};

// Reads the map in `directory` (the GIL released meanwhile).
std::shared_ptr<MapHandle> ReadMapHandle(const std::filesystem::path& directory);

// The map directory a Python argument names: a vmap.Map or a path.
std::filesystem::path MapDirectory(const pybind11::object& map_or_path);

}  // namespace vmap::python
