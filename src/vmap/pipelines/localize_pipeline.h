#pragma once
// The localization pipeline: a map and a repeat run in, every frame's key image, next key image, heading and
// pose out. Its set-up (LocalizationSession: the map read once, the route, the query, the key images, the
// localizer following the map) is what a robot keeps while it drives, one frame at a time (vmap.Localizer, the
// ROS node, the simulator); RunLocalizePipeline runs it over a whole query (`vmap localize MAP QUERY`,
// vmap.localize) and writes its CSV, JSON and report.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/control/odometry_progress.h"
#include "vmap/core/option_fields.h"
#include "vmap/localization/localization_map.h"
#include "vmap/localization/localization_output.h"
#include "vmap/localization/localize_sequence.h"
#include "vmap/localization/localizer.h"
#include "vmap/localization/route.h"
#include "vmap/sources/frame_source.h"

namespace vmap {

// How a map is opened and followed: what a robot keeps while it drives (vmap.Localizer, the ROS node, the
// simulator take these alone).
struct LocalizationSessionOptions {
  // The localizer's options; its verifier, definition of S, translation thresholds and camera follow the map
  // (FollowMap): they have no field here.
  LocalizerOptions localizer;
  int from = -1;                   // the route's first key image; -1 = the first
  int to = -1;                     // its last; -1 = the last
  RouteOptions route;              // how that route is planned: as `vmap route` plans it
  LocalizeSequenceOptions run;     // how a sequence's frames are read and their features extracted
  bool cache = true;               // read and write the key-image cache in the map directory
  MatcherRunSettings matcher_run;  // where a deep matcher computes in this run, and the weights it reads
  // The teach run's odometry (ReadTeachOdometry): a CSV or a recording with a nav_msgs/Odometry topic; "" = the map
  // folder's teach_odometry.csv, if any. With it and each frame's odometry, the localizer's motion model moves by the
  // distance driven (localization/motion_pace.h).
  std::string teach_odometry;
  std::string teach_odometry_topic;  // "" = the recording's only one

  // The fields above, each once, by the paths their checks name ("min_verified", "ranking.method",
  // "extraction_threads").
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
  // Throws OptionError when a field a user gave (`given`: their paths) is one the acceptance rule chosen does
  // not read: min_verified and min_similarity belong to acceptance counts, min_link_share, min_rival_ratio,
  // rival_max_log10_nfa, min_heading_rival_ratio and min_heading_votes to acceptance chance. Front ends know what was
  // given; a default is read by no rule that ignores it.
  void CheckGiven(const std::vector<std::string>& given) const;
};

struct LocalizePipelineOptions {
  std::string map;     // the map directory
  std::string query;   // a video, image folder, dataset, one image or live input; "" for frames given one at a time
  std::string csv;     // one row per frame; "" = none
  std::string json;    // the run (summary and every frame); "" = none
  std::string report;  // a folder for the run's HTML report; "" = none
  // The query's frames; `resize` "" = the map's frame size, where the map's camera holds.
  FrameSourceOptions source;
  LocalizationSessionOptions session;
  // The query's odometry (pipelines/localize_odometry.h): a CSV of timestamp,x,y,yaw or a recording with a
  // nav_msgs/Odometry topic; "" = the query recording's own, if any. With it the CSV and JSON gain its columns.
  std::string odometry;
  std::string odometry_topic;  // "" = the recording's only one

  // The fields above, each once, by the paths their checks name ("first", "min_verified", "csv").
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

// The route `from` and `to` plan on `map` (`route` when neither is given).
std::vector<int> RouteOf(const VisualMap& map, const LocalizationSessionOptions& options, std::vector<int> route);

struct LocalizePipelineResult {
  LocalizationRun run;       // what was localized, the summary and every frame's result, in order
  VisualMap map;             // the map localized against
  bool with_camera = false;  // the map's camera applied: headings in degrees and relative poses
};

// A map opened for localization, with a localizer on it, and the query when the options name one. Its frames are one
// run, given in order: one thread at a time (a host that shares a session between threads serializes the calls, as
// the Python module's Localizer does).
class LocalizationSession {
 public:
  // The set-up, stages in order; everything that can fail fast does before the key images are loaded (which may
  // take seconds):
  //   1. check the options;
  //   2. check the outputs (none may overwrite the map, the query or each other) and the query (no FIFO);
  //   3. read the map, once (ReadRecordedMap), the teach run's odometry, if any (ReadTeachOdometry), and the
  //      query's (`odometry`, a pipeline's: OpenQueryOdometry), so that a bad file is refused before any work;
  //   4. plan the route (from, to);
  //   5. open the query, at the map's frame size unless `source.resize` says otherwise;
  //   6. create the map's matcher (`matcher_run`: its device and weights in this run) and load its key images and
  //      experiences (cached in the map directory);
  //   7. make the localizer follow the map: its verifier, S, translation thresholds and camera, and its pace the
  //      teach odometry.
  // Throws InputError (OptionError for an option) naming what is wrong and how to fix it.
  explicit LocalizationSession(const LocalizePipelineOptions& options);
  ~LocalizationSession();
  LocalizationSession(LocalizationSession&&) noexcept;
  LocalizationSession& operator=(LocalizationSession&&) noexcept;

  const LocalizationMap& opened() const { return *opened_; }
  const VisualMap& map() const { return opened_->map; }
  const Matcher& matcher() const { return *opened_->matcher; }
  const LocalizerOptions& localizer_options() const { return options_; }  // following the map
  // The teach run's odometry the localizer is paced by (empty: none), on the key images' clock.
  const std::vector<OdometrySample>& teach_odometry() const { return teach_odometry_; }
  Localizer& localizer() { return *localizer_; }
  // The query's frames as opened (resize resolved); null without a query.
  FrameSource* query() { return query_.get(); }
  const FrameSourceOptions& query_options() const { return query_options_; }

  // The robot's loop: one image (uint8 grey or BGR, of any size: brought to the map's frame size), the next
  // frame of the run; `timestamp` in seconds when known; `odometry` the robot's odometry pose at the frame's time
  // when it has one (with the teach odometry, the belief moves by the distance driven). Features are extracted with
  // the map's matcher.
  LocalizationResult Localize(const cv::Mat& image, std::optional<double> timestamp = std::nullopt,
                              const std::optional<OdometrySample>& odometry = std::nullopt);
  // Forgets the estimate: the next frame is relocalized.
  void Reset();

 private:
  friend LocalizePipelineResult RunLocalizePipeline(const LocalizePipelineOptions& options,
                                                    const LocalizationCallback& on_frame);

  std::unique_ptr<LocalizationMap> opened_;
  LocalizerOptions options_;
  std::unique_ptr<Localizer> localizer_;
  std::vector<OdometrySample> teach_odometry_;
  std::optional<OdometryProgress> query_odometry_;  // RunLocalizePipeline's, taken there
  FrameSourceOptions query_options_;
  std::unique_ptr<FrameSource> query_;
  int frames_ = 0;  // frames given to Localize: the next one's index
};

// Localizes every frame of `options.query` (LocalizationSession, then LocalizeSequence) and writes the outputs
// asked for. `on_frame` sees each frame and its result, in order, as soon as it is known. Stages, in order:
//   1-7. the session's set-up (above);
//   8. take the query's odometry the session read, if any (each frame's pose paces the belief, with the teach
//      odometry);
//   9. localize every frame, keeping the CSV's rows (with the odometry's columns) and, for a report whose query
//      cannot be read again, the last frames it shows;
//  10. write the CSV, the JSON and the report.
LocalizePipelineResult RunLocalizePipeline(const LocalizePipelineOptions& options,
                                           const LocalizationCallback& on_frame = {});

}  // namespace vmap
