#pragma once
// MapBuilder: the incremental builder around KeyImageSelector (frames pushed one at a time, their features
// extracted and compared ahead on worker threads, the map written through a MapWriter).

#include <memory>
#include <string>
#include <vector>

#include "vmap/features/matcher.h"
#include "vmap/map/visual_map.h"
#include "vmap/mapping/map_builder_options.h"
#include "vmap/sources/frame_source.h"

namespace vmap {

class MapWriter;

// Builds a map one frame at a time: Algorithm 1 with the sequential search, streaming, so that a live input
// (a camera, a network stream) gets a map while it runs (Snapshot) and at any end (Finish). Frames pushed with
// Add() go to `prefetch_frames` worker threads that extract their features and compare them with the key
// images ahead of Algorithm 1, which takes them in order; Add() returns once the frame is handed over (it waits
// only when that many frames are in flight), so the caller decodes the next frame meanwhile.
//
// With a MapWriter, the map is written through it: key images as they are chosen, evaluations to a file as
// they are made (memory stays flat for any length: the returned map's `evaluations` are then empty, map.json
// has them all), map.json and correspondences.bin at Finish. Without one, the map is only returned, with its
// evaluations in memory. The same options and frames give the same map as BuildMap, whatever the threads do.
class MapBuilder {
 public:
  // One map at options.key_images.tau. `source` gives the input's description (info(), skipped_frames()) as it
  // is known when a map is written; the frames come through Add(). Refuses key_search bisect (OptionError), which
  // reads ahead of the frames it is given.
  MapBuilder(const FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
             MapWriter* writer = nullptr, std::string options_json = "{}");
  // One map per threshold over one pass (a sweep): each frame's features are extracted once, and a pair compared
  // for several taus is matched once. writers[i] (may be null) receives tau i's map.
  MapBuilder(const FrameSource& source, const Matcher& matcher, const MapBuilderOptions& options,
             std::vector<double> taus, std::vector<MapWriter*> writers, std::string options_json = "{}");
  ~MapBuilder();
  MapBuilder(const MapBuilder&) = delete;
  MapBuilder& operator=(const MapBuilder&) = delete;

  // The next frame of the input (in order).
  void Add(Frame frame);
  // Writes the map of the frames taken so far through each writer that has a snapshot target: a consistent map
  // (the key images chosen so far and their links, no final key image), committed atomically.
  void Snapshot();
  // Ends the input: the final key image, full link verification and analysis, each map written through its
  // writer. `end` is recorded in the map (VisualMap::coverage) when it is not kInputEnded, and for an input of
  // unknown length. `analyze_links` false skips each link's pose, parallax and homography test (sweep tables).
  // `with_evaluations`: the maps returned have their evaluations even when a writer took them (read back from
  // its file: the whole map in memory, for batch callers).
  std::vector<VisualMap> FinishAll(CoverageEnd end = CoverageEnd::kInputEnded, bool analyze_links = true,
                                   bool with_evaluations = false);
  VisualMap Finish(CoverageEnd end = CoverageEnd::kInputEnded);  // the one map

  long features_extracted() const;  // one per frame: no frame is extracted twice
  long pairs_matched() const;       // pairs matched and verified, including a few made ahead and not needed
  long links_verified() const;      // links verified in full after an early-stopped decision

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};
}  // namespace vmap
