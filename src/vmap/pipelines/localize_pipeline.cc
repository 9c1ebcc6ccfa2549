#include "vmap/pipelines/localize_pipeline.h"

#include <algorithm>
#include <filesystem>
#include <optional>
#include <utility>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "vmap/core/atomic_output.h"
#include "vmap/core/error.h"
#include "vmap/localization/localizer.h"
#include "vmap/localization/route.h"
#include "vmap/map/map_io.h"
#include "vmap/mapping/recorded_options.h"
#include "vmap/pipelines/localize_odometry.h"
#include "vmap/pipelines/output_policies.h"
#include "vmap/report/localization_report.h"
#include "vmap/sources/image_frame.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

// A FIFO or a device other than a camera would be opened blocking, waiting for a writer that may never come.
void CheckQueryIsNoFifo(const std::string& query) {
  std::error_code ec;
  const fs::file_status status = fs::status(query, ec);
  if (!IsLiveInput(query) && fs::exists(status) && !fs::is_regular_file(status) && !fs::is_directory(status)) {
    throw InputError("query '" + query +
                     "' is neither a file nor a folder (a FIFO or a device); give a video, an image folder, a "
                     "TUM/EuRoC/KITTI sequence, an image, or a live input (udp://..., /dev/videoN)");
  }
}

}  // namespace

void LocalizationSessionOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Section("Route and odometry");
  visitor.Visit(OptionField{"from", "--from", "Follow the route from this key image (default: the first)"}
                    .AtLeast(0)
                    .Or(-1)
                    .Meaning("-1: the first")
                    .HideDefault()
                    .NotRecorded(),
                from);
  visitor.Visit(OptionField{"to", "--to", "Follow the route to this key image (default: the last)"}
                    .AtLeast(0)
                    .Or(-1)
                    .Meaning("-1: the last")
                    .HideDefault()
                    .NotRecorded(),
                to);
  visitor.VisitNested("", route);
  visitor.Visit(OptionField{"teach_odometry", "--teach-odometry",
                            "The teach run's odometry: a CSV of timestamp,x,y,yaw (s, m, rad) or a recording with a "
                            "nav_msgs/Odometry topic, on the key images' clock; with the frames' odometry the belief "
                            "moves by the distance driven (default: the map folder's teach_odometry.csv, if any)"}
                    .HideDefault()
                    .NotRecorded(),
                teach_odometry);
  visitor.Visit(OptionField{"teach_odometry_topic", "--teach-odometry-topic",
                            "The teach recording's nav_msgs/Odometry topic to read (default: its only one)"}
                    .HideDefault()
                    .NotRecorded(),
                teach_odometry_topic);
  // The verifier and the translation thresholds follow the map (FollowMap): no field of the session's.
  visitor.VisitNested("", localizer, Nesting{false, {"verifier", "translation"}});
  visitor.Section(kRunSection);
  visitor.VisitNested("", run);
  visitor.Visit(OptionField{"cache", "!--no-cache", "Do not read or write the key-image cache in the map directory"}
                    .NotRecorded(),
                cache);
  visitor.VisitNested("", matcher_run);
}

void LocalizationSessionOptions::Check() const {
  run.Check();
  localizer.Check();
  route.Check();
  matcher_run.Check();
  // -1 stands for "not given"; any other negative key image is refused as the route refuses it.
  for (const auto& [name, key] : {std::pair<const char*, int>{"from", from}, {"to", to}}) {
    if (key < -1) throw OptionError(name, fmt::format("{} is no key image; give 0 or more", key));
  }
}

void LocalizationSessionOptions::CheckGiven(const std::vector<std::string>& given) const {
  const auto was_given = [&](const char* path) { return std::find(given.begin(), given.end(), path) != given.end(); };
  if (localizer.acceptance != AcceptanceRule::kCounts) {
    for (const char* path : {"min_verified", "min_similarity"}) {
      if (was_given(path)) {
        throw OptionError(path, "belongs to acceptance counts (the earlier rule); give that too, or leave it out",
                          {"acceptance"});
      }
    }
  }
  if (localizer.acceptance != AcceptanceRule::kChance) {
    for (const char* path : {"min_link_share", "link_share_tau", "min_rival_ratio", "rival_max_log10_nfa",
                             "min_heading_rival_ratio", "min_heading_votes"}) {
      if (was_given(path)) {
        throw OptionError(path, "belongs to acceptance chance; give that, or leave it out", {"acceptance"});
      }
    }
  }
}

void LocalizePipelineOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit(OptionField{"map", "map", "Map directory written by `vmap build`"}.Positional(), map);
  visitor.Visit(
      OptionField{"query", "query", "Video, image folder, TUM/EuRoC/KITTI sequence, or a single image"}.Positional(),
      query);
  visitor.Section(kOutputSection);
  visitor.Visit(OptionField{"csv", "--csv", "Write one row per frame to this CSV file"}.HideDefault().NotRecorded(),
                csv);
  visitor.Visit(OptionField{"json", "--json", "Write the run (summary and every frame) to this JSON file"}
                    .HideDefault()
                    .NotRecorded(),
                json);
  visitor.Visit(OptionField{"report", "--report", "Write an HTML report of the run into this directory"}
                    .HideDefault()
                    .NotRecorded(),
                report);
  visitor.VisitNested("", source);
  visitor.VisitNested("", session);
  visitor.Section("Route and odometry");
  visitor.Visit(OptionField{"odometry", "--odometry",
                            "Odometry of the query: a CSV of timestamp,x,y,yaw (s, m, rad) or a recording with a "
                            "nav_msgs/Odometry topic (default: the query recording's own, if any)"}
                    .HideDefault()
                    .NotRecorded(),
                odometry);
  visitor.Visit(OptionField{"odometry_topic", "--odometry-topic",
                            "The nav_msgs/Odometry topic to read (default: the recording's only one)"}
                    .HideDefault()
                    .NotRecorded(),
                odometry_topic);
}

void LocalizePipelineOptions::Check() const {
  source.Check();
  session.Check();
}

std::vector<int> RouteOf(const VisualMap& map, const LocalizationSessionOptions& options, std::vector<int> route) {
  if (options.from < 0 && options.to < 0) return route;
  const int last = static_cast<int>(map.key_images.size()) - 1;
  CheckKeyImageOption(map, options.from, "from");
  CheckKeyImageOption(map, options.to, "to");
  return PlanRoute(map, options.from >= 0 ? options.from : 0, options.to >= 0 ? options.to : last, options.route).keys;
}

LocalizationSession::LocalizationSession(const LocalizePipelineOptions& options) {
  // 1. The options.
  options.Check();

  // 2. The outputs and the query, before any reading.
  CheckOutputs(
      {{options.csv, "csv"}, {options.json, "json"}},
      {MapInputs(options.map), NamedInput(options.query, "the query"), NamedInput(options.report, "the report folder"),
       NamedInput(options.odometry, "the odometry"), NamedInput(options.session.teach_odometry, "the teach odometry"),
       ExistingInputs({options.source.camera}, "the camera file"),
       ExistingInputs({options.session.matcher_run.weights}, "the weights file")});
  if (!options.report.empty()) CheckLocalizationReportDirectory(options.report, options.map, options.query);
  if (!options.query.empty()) CheckQueryIsNoFifo(options.query);

  // 3. The map, read once, and the runs' odometry.
  RecordedMap read = ReadRecordedMap(options.map);
  teach_odometry_ =
      ReadTeachOdometry(options.map, options.session.teach_odometry, options.session.teach_odometry_topic);
  query_odometry_ = OpenQueryOdometry(options.odometry, options.odometry_topic, options.query);

  // 4. The route.
  LocalizerOptions localizer = options.session.localizer;
  localizer.route = RouteOf(read.map, options.session, localizer.route);
  CheckStartKey(read.map, localizer);

  // 5. The query: frames are compared with key images at the map's size unless told otherwise.
  query_options_ = options.source;
  query_options_.allow_single_image = true;
  query_options_.resize = QueryResize(read.map, query_options_.resize);
  if (!options.query.empty()) query_ = OpenFrameSource(options.query, query_options_);

  // 6. The map's matcher (a deep model loads its weights here), key images and experiences.
  std::unique_ptr<Matcher> matcher = CreateMapMatcher(read, options.map, options.session.matcher_run);
  KeyImageStoreOptions store_options;
  store_options.use_cache = options.session.cache;
  store_options.thumbnail_width = localizer.ranking.thumbnail_width;
  opened_ = std::make_unique<LocalizationMap>(
      OpenLocalizationMap(std::move(read), options.map, store_options, std::move(matcher)));

  // 7. The localizer, following the map: its verifier, definition of S, translation thresholds and camera.
  options_ = FollowMap(*opened_, localizer, query_options_.resize);
  options_.Check();
  localizer_ = std::make_unique<Localizer>(opened_->map, opened_->keys, *opened_->matcher, options_);
  const bool paced_by_odometry = localizer_->PaceByTeachOdometry(teach_odometry_);
  if (!teach_odometry_.empty()) {
    const std::string read_from = options.session.teach_odometry.empty()
                                      ? (std::filesystem::path(options.map) / kTeachOdometryFileName).string()
                                      : options.session.teach_odometry;
    if (paced_by_odometry) {
      spdlog::info(
          "teach odometry  {} samples from {}: with the frames' odometry the belief moves by the distance driven",
          teach_odometry_.size(), read_from);
    } else {
      // Said, not refused: the teach odometry still gives the controller its taught profile where it covers the route.
      spdlog::warn(
          "the teach odometry {} does not cover two of the route's key images at their times, or not along "
          "one direction; the belief is paced by time, or by input index",
          read_from);
    }
  }
}

LocalizationSession::~LocalizationSession() = default;
LocalizationSession::LocalizationSession(LocalizationSession&&) noexcept = default;
LocalizationSession& LocalizationSession::operator=(LocalizationSession&&) noexcept = default;

LocalizationResult LocalizationSession::Localize(const cv::Mat& image, std::optional<double> timestamp,
                                                 const std::optional<OdometrySample>& odometry) {
  Frame frame = FrameFromImage(image, frames_, opened_->map.input.frame_size, "image");
  if (timestamp) frame.timestamp = *timestamp;
  frame.odometry = odometry;
  const auto features = opened_->matcher->ExtractFrame(frame.gray, frame.color);
  LocalizationResult result = localizer_->Localize(frame, *features);
  ++frames_;
  return result;
}

void LocalizationSession::Reset() { localizer_->Reset(); }

LocalizePipelineResult RunLocalizePipeline(const LocalizePipelineOptions& options,
                                           const LocalizationCallback& on_frame) {
  // 1-7. The set-up.
  if (options.query.empty())
    throw OptionError("query", "is empty; give a video, an image folder, a dataset or an image");
  LocalizationSession session(options);
  FrameSource& query = *session.query();
  const LocalizationMap& opened = session.opened();
  const VisualMap& map = opened.map;

  // 8. The odometry: with it, its columns come last on every row (CSV and JSON), and each frame's pose paces the
  // belief where the session has the teach odometry.
  std::optional<OdometryProgress> odometry = std::move(session.query_odometry_);
  nlohmann::json odometry_json = nlohmann::json::array();

  // 9. Every frame.
  LocalizeSequenceOptions run_options = options.session.run;
  run_options.show_progress = run_options.show_progress && spdlog::should_log(spdlog::level::info);
  LocalizePipelineResult result;
  LocalizationRun& run = result.run;
  run.info.map_directory = options.map;
  run.info.query = options.query;
  run.info.query_format = query.info().format;
  run.info.source = session.query_options();
  run.info.matcher = opened.matcher->name();
  run.info.ranking = RankingMethodName(session.localizer().ranking_method());
  run.info.cache = KeyImageCacheStateName(opened.keys.cache);
  run.info.key_image_seconds = opened.keys.seconds;
  run.info.options_json = DescribeLocalizerOptions(session.localizer_options());
  run.info.experiences = !opened.experiences.empty();
  std::string csv = LocalizationCsvHeader(run.info.experiences);
  if (odometry) csv.insert(csv.size() - 1, OdometryCsvColumns());
  // A query that cannot be read again (a live input, a single image) leaves its report the frames kept here:
  // the last ones, as many as the report shows.
  const LocalizationReportOptions report_options;
  const bool record = !options.report.empty() && !QueryCanBeReadAgain(run.info);
  RecordedFrames recorded;
  const OdometryTrack* odometry_track = odometry ? &odometry->track() : nullptr;
  run.summary = LocalizeSequence(
      query, *opened.matcher, session.localizer(), run_options,
      [&](const Frame& frame, const LocalizationResult& frame_result) {
        std::string row = LocalizationCsvRow(map, frame_result, run.info.experiences);
        if (odometry) {
          const FrameOdometry at = odometry->Update(frame_result);
          row.insert(row.size() - 1, OdometryCsvCells(at));
          odometry_json.push_back(OdometryJson(frame_result.frame_index, at));
        }
        if (!options.csv.empty()) csv += row;
        run.frames.push_back(frame_result);
        if (record && report_options.pairs > 0) {
          recorded[frame_result.frame_index] = ColorImage(frame);
          if (recorded.size() > static_cast<size_t>(report_options.pairs)) {
            recorded.erase(recorded.begin());
          }
        }
        if (on_frame) on_frame(frame, frame_result);
      },
      odometry_track);
  run.info.frame_size = query.info().frame_size;

  // 10. The outputs: all written before any is put in place, so that a failure while writing one (a full disk)
  // leaves every output of an earlier run as it was. The report, the one most likely to be refused as it is put in
  // place (its folder changed meanwhile), goes first.
  std::optional<PendingFile> csv_file;
  if (!options.csv.empty()) csv_file.emplace(options.csv, csv);
  std::optional<PendingFile> json_file;
  if (!options.json.empty()) {
    std::string json = LocalizationRunJson(map, run);
    if (odometry) {
      nlohmann::json document = nlohmann::json::parse(json);
      document["odometry"] = std::move(odometry_json);
      json = document.dump(1) + "\n";
    }
    json_file.emplace(options.json, json);
  }
  if (!options.report.empty()) {
    PrepareLocalizationReport(run, map, options.map, options.report, report_options, recorded)->Commit();
  }
  if (json_file) json_file->Commit();
  if (csv_file) csv_file->Commit();
  result.with_camera = session.localizer_options().camera.has_value();
  result.map = std::move(session.opened_->map);  // the session, done, is not used again
  return result;
}

}  // namespace vmap
