#pragma once
// vmap.Map, vmap.KeyImage and vmap.Link: a map directory as ReadMap reads it, its key images decoded only when
// asked for (a long map's images would not fit in memory at once).

#include <filesystem>
#include <memory>
#include <optional>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "vmap/core/file_identity.h"
#include "vmap/map/visual_map.h"
#include "vmap/mapping/recorded_options.h"

namespace vmap::python {

struct MapHandle {
  std::filesystem::path directory;
  VisualMap map;
  RecordedOptions options;  // what the map records of the options that shaped it, typed
  // The folder's and its map.json's identities when it was read. vmap replaces a map's folder whole (a rename), so
  // another folder at the path is another map, whose key images do not belong to these links; map.json's time
  // tells a copy that took the inode of a removed folder.
  std::optional<FileIdentity> folder_identity, map_json_identity;

  // Whether the folder at `directory` is still the one read (no map built into it since).
  bool Unchanged() const;
  // Throws InputError when it is not.
  void CheckUnchanged() const;
};

// Reads the map in `directory` (the GIL released meanwhile).
std::shared_ptr<MapHandle> ReadMapHandle(const std::filesystem::path& directory);

// Reads back the map a build just committed to `directory`, which `built` is: another build into the same folder
// may have replaced it since (two threads given one output), and then the map read is not the one built.
std::shared_ptr<MapHandle> ReadBuiltMapHandle(const std::filesystem::path& directory, const VisualMap& built);

// The map directory a Python argument names: a vmap.Map or a path.
std::filesystem::path MapDirectory(const pybind11::object& map_or_path);

}  // namespace vmap::python
