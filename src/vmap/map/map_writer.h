#pragma once
// The one sink a map is written through while it is built: key images as they are chosen (on a thread of their
// own), the evaluations appended to a file as they are made, then map.json and correspondences.bin; and, while
// the build goes on, snapshots: complete maps committed atomically at the output's final path.
//
// Memory stays flat however long the input: a build makes one evaluation per frame or more, so they are not
// kept in memory but appended to a file in the map's own (temporary) directory, and map.json is written from
// that file column by column (WriteMapJson). Key images and links, which grow with the map itself, stay in
// memory.

#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "vmap/core/atomic_output.h"
#include "vmap/map/map_io.h"
#include "vmap/map/visual_map.h"
#include "vmap/sources/frame_source.h"

namespace vmap {

// The evaluations' file while a map is built; removed once map.json is written.
inline constexpr const char* kEvaluationsSpillFileName = "evaluations.partial";
// The bytes of one evaluation in that file: its fields alone, no padding (map_writer.cc).
inline constexpr std::size_t kEvaluationRecordSize = 4 * sizeof(int) + sizeof(double) + sizeof(bool);

// Where Snapshot() commits its maps.
struct SnapshotTarget {
  std::filesystem::path final_path;  // the map directory being built (`vmap build -o`)
  OutputPolicy policy;               // what may be replaced there (the previous snapshot is a vmap map)
  // Writes the host's own files into each snapshot's folder before it is committed (may be empty).
  std::function<void(const std::filesystem::path& snapshot_folder)> write_beside;
};

class MapWriter {
 public:
  // `directory` must exist and is the writer's until Finish (the path() of an AtomicOutputDirectory, whose
  // Commit the caller makes). Snapshot() needs `snapshots`.
  explicit MapWriter(std::filesystem::path directory, std::optional<SnapshotTarget> snapshots = std::nullopt);
  ~MapWriter();  // never throws; removes the evaluations' file when Finish was not reached
  MapWriter(const MapWriter&) = delete;
  MapWriter& operator=(const MapWriter&) = delete;

  const std::filesystem::path& directory() const { return directory_; }

  // Queues `frame`, a new key image, to be written into keys/; returns its file name relative to the map
  // (keys/NNNNNN.png, or keys/NNNNNN.jpg etc. when it is a copy of its input image file).
  std::string AddKeyImage(std::shared_ptr<const Frame> frame);
  // Waits until every key image queued so far is in directory() (to be read back: the links' cross-check).
  void FlushKeyImages();
  void AddEvaluation(const Evaluation& evaluation);
  long num_evaluations() const { return num_evaluations_; }

  // Commits `map` (its evaluations: the ones added here; map.evaluations is ignored) as a complete map at the
  // snapshot target, replacing the previous snapshot in one rename: a reader sees the old map or the new one.
  // Key images are hard links to the ones written here (copies where the file system has none).
  void Snapshot(const VisualMap& map);
  // Waits for the key images, writes map.json (evaluations from here) and correspondences.bin into
  // directory() and removes the evaluations' file. The caller then commits the directory. `read_back`: also
  // every evaluation, read back before the file goes (for callers that want the whole map in memory).
  void Finish(const VisualMap& map, std::vector<Evaluation>* read_back = nullptr);

 private:
  class KeyImageFiles;
  void WriteMapAndCorrespondences(const VisualMap& map, const std::filesystem::path& directory);
  EvaluationSource Evaluations();

  std::filesystem::path directory_;
  std::optional<SnapshotTarget> snapshots_;
  std::unique_ptr<KeyImageFiles> key_images_;
  std::FILE* evaluations_ = nullptr;
  long num_evaluations_ = 0;
  bool finished_ = false;
};

}  // namespace vmap
