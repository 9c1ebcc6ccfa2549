#include "vmap/pipelines/localize_pipeline.h"

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "vmap/core/error.h"
#include "vmap/features/camera_mask.h"
#include "vmap/localization/localization_map.h"
#include "vmap/localization/motion_pace.h"
#include "vmap/map/map_io.h"
#include "vmap/pipelines/build_pipeline.h"
#include "vmap/pipelines/localize_odometry.h"
#include "vmap/sources/odometry.h"
#include "vmap/testing/localization_test_util.h"
#include "vmap/testing/option_error.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace {
namespace fs = std::filesystem;

// How the drive's map is built: within a camera mask; the teach folder with a timestamps.txt, its frames
// `seconds_per_frame` apart (0: none); at Algorithm 1's `tau` (unset: the matcher's).
struct DriveOptions {
  cv::Mat camera_mask;
  double seconds_per_frame = 0.0;
  std::optional<double> tau;
};

// A map of the drive's even frames, and its odd frames as the repeat run.
struct Drive {
  testing::ScopedTempDir tmp;
  fs::path map = tmp.path() / "map";
  fs::path repeat = tmp.path() / "repeat";

  explicit Drive(const DriveOptions& drive = {}) {
    testing::WriteImageFolder(testing::SidewaysDrive(), tmp.path() / "teach");
    if (drive.seconds_per_frame > 0.0) {
      std::ofstream times(tmp.path() / "teach" / "timestamps.txt");
      for (size_t i = 0; i < testing::SidewaysDrive().frames.size(); ++i) {
        times << "frame_" << i + 1 << ".png " << drive.seconds_per_frame * static_cast<double>(i) << "\n";
      }
    }
    BuildPipelineOptions build;
    if (!drive.camera_mask.empty()) {
      build.matcher.camera_mask = (tmp.path() / "mask.png").string();
      cv::imwrite(build.matcher.camera_mask, drive.camera_mask);
    }
    build.tau = drive.tau;
    build.input = (tmp.path() / "teach").string();
    build.output = map.string();
    build.source.stride = 2;
    build.map.show_progress = false;
    RunBuildPipeline(build);
    fs::create_directory(repeat);
    const std::vector<int> odd = testing::DriveIndices(1, 2);
    for (size_t i = 0; i < odd.size(); ++i) {
      fs::copy_file(tmp.path() / "teach" / ("frame_" + std::to_string(odd[i] + 1) + ".png"),
                    repeat / ("frame_" + std::to_string(i + 1) + ".png"));
    }
  }

  LocalizePipelineOptions Options() const {
    LocalizePipelineOptions options;
    options.map = map.string();
    options.query = repeat.string();
    options.session.cache = false;
    options.session.run.show_progress = false;
    return options;
  }
};

// A camera mask of the drive's frames that hides their `columns` leftmost columns.
cv::Mat MaskHiding(int columns) {
  cv::Mat mask(testing::SidewaysDrive().frames.at(0).size(), CV_8UC1, cv::Scalar(255));
  mask.colRange(0, columns).setTo(0);
  return mask;
}

// A map built within a camera mask keeps it, and its key images and the frames are extracted within it: the
// frames localize as they do on a map without one (the mask hides a quarter of a scene that has features there).
TEST(LocalizePipeline, AMapBuiltWithinACameraMaskLocalizesWithinIt) {
  const cv::Size size = testing::SidewaysDrive().frames.at(0).size();
  const cv::Mat mask = MaskHiding(size.width / 4);
  DriveOptions masked;
  masked.camera_mask = mask;
  Drive drive(masked);
  const LocalizePipelineResult run = RunLocalizePipeline(drive.Options(), nullptr);
  ASSERT_EQ(run.map.camera_mask.size(), size);
  EXPECT_EQ(cv::countNonZero(run.map.camera_mask != mask), 0);
  int placed = 0;
  for (const LocalizationResult& frame : run.run.frames) placed += IsPlaced(frame.status);
  EXPECT_GE(placed, static_cast<int>(run.run.frames.size()) * 9 / 10);

  const LocalizationMap opened = OpenLocalizationMap(drive.map, KeyImageStoreOptions{});
  ASSERT_NE(CameraMaskOf(*opened.matcher), nullptr);
  ASSERT_GE(opened.keys.features.size(), 2u);
  const TentativeMatches matches = opened.matcher->Match(*opened.keys.features[0], *opened.keys.features[1]);
  ASSERT_GT(matches.size(), 10u);
  for (const cv::Point2f& p : matches.points0) EXPECT_GE(p.x, size.width / 4 - 0.5f);
  const cv::Mat first = cv::imread((drive.repeat / "frame_1.png").string(), cv::IMREAD_GRAYSCALE);
  const TentativeMatches frame_matches =
      opened.matcher->Match(*opened.matcher->Extract(first), *opened.keys.features[0]);
  ASSERT_GT(frame_matches.size(), 10u);
  for (const cv::Point2f& p : frame_matches.points0) EXPECT_GE(p.x, size.width / 4 - 0.5f);
}

// A mask swapped for another of the same size since the build would extract the frames elsewhere than the key images
// were: refused against the digest the map's record keeps, naming the file and the fix.
TEST(LocalizePipeline, AMapWhoseCameraMaskWasSwappedIsRefused) {
  const int width = testing::SidewaysDrive().frames.at(0).cols;
  DriveOptions masked;
  masked.camera_mask = MaskHiding(width / 4);
  Drive drive(masked);
  cv::imwrite((drive.map / kCameraMaskFileName).string(), MaskHiding(width / 2));
  try {
    RunLocalizePipeline(drive.Options(), nullptr);
    ADD_FAILURE() << "a swapped camera mask was accepted";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("camera_mask.png is not the mask the map was built with"),
              std::string::npos)
        << error.what();
  }
}

// The robot's loop (one image at a time through the session) localizes every frame as the whole run does.
TEST(LocalizePipeline, TheSessionFrameByFrameEqualsTheRun) {
  Drive drive;
  LocalizePipelineOptions options = drive.Options();
  options.csv = (drive.tmp.path() / "run.csv").string();
  int seen = 0;
  const LocalizePipelineResult run =
      RunLocalizePipeline(options, [&](const Frame&, const LocalizationResult&) { ++seen; });
  ASSERT_GT(run.run.frames.size(), 10u);
  EXPECT_EQ(seen, static_cast<int>(run.run.frames.size()));
  EXPECT_TRUE(fs::is_regular_file(options.csv));
  EXPECT_GE(run.map.key_images.size(), 2u);

  LocalizePipelineOptions session_options = drive.Options();
  session_options.query.clear();
  LocalizationSession session(session_options);
  EXPECT_EQ(session.query(), nullptr);
  for (size_t i = 0; i < run.run.frames.size(); ++i) {
    const cv::Mat gray =
        cv::imread((drive.repeat / ("frame_" + std::to_string(i + 1) + ".png")).string(), cv::IMREAD_GRAYSCALE);
    const LocalizationResult result = session.Localize(gray);
    const LocalizationResult& expected = run.run.frames[i];
    EXPECT_EQ(result.status, expected.status) << i;
    EXPECT_EQ(result.key, expected.key) << i;
    EXPECT_EQ(result.next_key, expected.next_key) << i;
    EXPECT_EQ(result.to_key.num_verified, expected.to_key.num_verified) << i;
  }
}

// A map of places, its teach run timed: every other teach frame a key image, 0.1 s apart.
DriveOptions TimedPlaces() {
  DriveOptions timed_places;
  timed_places.seconds_per_frame = 0.1;
  timed_places.tau = 1.0;
  return timed_places;
}

// The mean spacing of a map's key images in its teach run (the whole map the route): input frames and seconds.
struct TeachSpacing {
  double frames = 0.0;
  double seconds = 0.0;
};

TeachSpacing TeachSpacingOf(const fs::path& map_directory) {
  const VisualMap map = ReadMap(map_directory);
  std::vector<int> source_indices;
  std::vector<double> times;
  for (const KeyImage& key : map.key_images) {
    source_indices.push_back(key.source_index);
    times.push_back(key.timestamp);
  }
  return {TeachFramesPerPosition(source_indices), TeachSecondsPerPosition(times)};
}

// A robot's loop that localizes one camera frame in four (or a camera at a quarter of the teach run's frame rate)
// passes four times as much of the route a frame as its frames' count says: given the frames' times, the belief's
// motion model moves as far as the time since the frame before says, at the teach run's pace between key images.
TEST(LocalizePipeline, TheSessionPacesTheBeliefByTheFramesTimes) {
  Drive drive(TimedPlaces());
  const TeachSpacing spacing = TeachSpacingOf(drive.map);
  ASSERT_GT(spacing.seconds, 0.0) << "the map keeps its key images' times";
  const int by_time = MotionStepsPerFrame(0.4, spacing.seconds);
  const int by_count = MotionStepsPerFrame(1, spacing.frames);
  ASSERT_GT(by_time, by_count) << "the drive's key images are too far apart for a frame in four to tell";

  auto steps_of_every_fourth_frame = [&](bool with_times) {
    LocalizePipelineOptions options = drive.Options();
    options.query.clear();
    LocalizationSession session(options);
    std::vector<int> steps;
    for (size_t i = 0; i < testing::SidewaysDrive().frames.size(); i += 4) {
      const cv::Mat gray = cv::imread(
          (drive.tmp.path() / "teach" / ("frame_" + std::to_string(i + 1) + ".png")).string(), cv::IMREAD_GRAYSCALE);
      steps.push_back(
          session.Localize(gray, with_times ? std::optional<double>(0.1 * static_cast<double>(i)) : std::nullopt)
              .motion_steps);
    }
    return steps;
  };
  const std::vector<int> timed = steps_of_every_fourth_frame(true);
  const std::vector<int> counted = steps_of_every_fourth_frame(false);
  ASSERT_GT(timed.size(), 5u);
  EXPECT_EQ(timed[0], 1) << "a run's first frame";
  EXPECT_EQ(counted[0], 1);
  for (size_t f = 1; f < timed.size(); ++f) {
    EXPECT_EQ(timed[f], by_time) << f;
    EXPECT_EQ(counted[f], by_count) << f;
  }
}

// A robot that repeats the route four times as fast as it was taught, its camera at about the teach run's frame rate:
// its frames' times say about a frame's worth of the teach run; its odometry, against the teach run's beside the map,
// says four. The whole run (the query's odometry file) and the robot's loop (a pose with each frame) pace the belief
// alike.
TEST(LocalizePipeline, TheOdometryPacesTheBeliefByTheDistanceDriven) {
  Drive drive(TimedPlaces());
  constexpr double kMetresPerTeachFrame = 0.05;
  constexpr double kRepeatSecondsPerFrame = 0.12;  // the teach run's 0.1 would put the pace by time at a half step
  auto pose_at = [](double seconds, double metres) {
    OdometrySample pose;
    pose.timestamp = seconds;
    pose.x = metres;
    return pose;
  };
  std::vector<OdometrySample> teach;
  for (size_t i = 0; i < testing::SidewaysDrive().frames.size(); ++i) {
    teach.push_back(pose_at(0.1 * static_cast<double>(i), kMetresPerTeachFrame * static_cast<double>(i)));
  }
  // The fast repeat: every fourth teach frame, at that frame's place.
  const fs::path fast = drive.tmp.path() / "fast";
  fs::create_directories(fast);
  std::vector<OdometrySample> repeat;
  std::ofstream times(fast / "timestamps.txt");
  for (size_t i = 0, f = 0; i < testing::SidewaysDrive().frames.size(); i += 4, ++f) {
    const std::string name = "frame_" + std::to_string(f + 1) + ".png";
    fs::copy_file(drive.tmp.path() / "teach" / ("frame_" + std::to_string(i + 1) + ".png"), fast / name);
    times << name << " " << kRepeatSecondsPerFrame * static_cast<double>(f) << "\n";
    repeat.push_back(
        pose_at(kRepeatSecondsPerFrame * static_cast<double>(f), kMetresPerTeachFrame * static_cast<double>(i)));
  }
  times.close();
  const fs::path repeat_odometry = drive.tmp.path() / "repeat_odometry.csv";
  std::ofstream(repeat_odometry) << OdometryCsv(repeat);

  // The odometry is 0.05 m a teach frame in both runs: a repeat frame drove four teach frames' worth.
  const TeachSpacing spacing = TeachSpacingOf(drive.map);
  const int by_distance = MotionStepsPerFrame(4, spacing.frames);
  const int by_time = MotionStepsPerFrame(kRepeatSecondsPerFrame, spacing.seconds);
  ASSERT_GT(by_distance, by_time) << "the drive's key images are too far apart for four frames to tell";

  // Without the teach odometry: by time, whatever the query's odometry.
  LocalizePipelineOptions options = drive.Options();
  options.query = fast.string();
  options.odometry = repeat_odometry.string();
  const LocalizePipelineResult untaught = RunLocalizePipeline(options);
  ASSERT_GT(untaught.run.frames.size(), 5u);
  for (size_t f = 1; f < untaught.run.frames.size(); ++f) EXPECT_EQ(untaught.run.frames[f].motion_steps, by_time) << f;

  // The teach odometry beside the map (as the ROS node's teach run writes it): by the distance driven.
  std::ofstream(drive.map / kTeachOdometryFileName) << OdometryCsv(teach);
  const LocalizePipelineResult taught = RunLocalizePipeline(options);
  ASSERT_EQ(taught.run.frames.size(), untaught.run.frames.size());
  EXPECT_EQ(taught.run.frames[0].motion_steps, 1) << "a run's first frame";
  for (size_t f = 1; f < taught.run.frames.size(); ++f) EXPECT_EQ(taught.run.frames[f].motion_steps, by_distance) << f;

  // The robot's loop, a pose with each frame: the same steps and places; without poses, by time.
  LocalizePipelineOptions session_options = drive.Options();
  session_options.query.clear();
  LocalizationSession session(session_options);
  ASSERT_EQ(session.teach_odometry().size(), teach.size());
  for (size_t f = 0; f < taught.run.frames.size(); ++f) {
    const cv::Mat gray =
        cv::imread((fast / ("frame_" + std::to_string(f + 1) + ".png")).string(), cv::IMREAD_GRAYSCALE);
    const LocalizationResult result = session.Localize(gray, repeat[f].timestamp, repeat[f]);
    EXPECT_EQ(result.motion_steps, taught.run.frames[f].motion_steps) << f;
    EXPECT_EQ(result.key, taught.run.frames[f].key) << f;
    EXPECT_EQ(result.status, taught.run.frames[f].status) << f;
  }
  session.Reset();
  session.Localize(cv::imread((fast / "frame_1.png").string(), cv::IMREAD_GRAYSCALE), 0.0);
  EXPECT_EQ(session.Localize(cv::imread((fast / "frame_2.png").string(), cv::IMREAD_GRAYSCALE), kRepeatSecondsPerFrame)
                .motion_steps,
            by_time);

  // A teach odometry named that cannot be read is refused, by name.
  options.session.teach_odometry = (drive.tmp.path() / "no_such_odometry.csv").string();
  try {
    RunLocalizePipeline(options);
    ADD_FAILURE() << "a missing teach odometry was read";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("no_such_odometry.csv"), std::string::npos) << error.what();
  }
}

// The teach odometry beside a map is the map's file: a link out of the map folder is refused, by name, as the map's
// own files are; without one the map localizes as it is.
TEST(LocalizePipeline, TheTeachOdometryBesideAMapIsReadOnlyInsideIt) {
  Drive drive;
  const fs::path outside = drive.tmp.path() / "elsewhere.csv";
  std::ofstream(outside) << "timestamp,x,y,yaw\n0,0,0,0\n1,1,0,0\n";
  fs::create_symlink(outside, drive.map / kTeachOdometryFileName);
  try {
    RunLocalizePipeline(drive.Options());
    ADD_FAILURE() << "a teach odometry out of the map folder was read";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find(kTeachOdometryFileName), std::string::npos) << message;
    EXPECT_NE(message.find("outside"), std::string::npos) << message;
  }
  fs::remove(drive.map / kTeachOdometryFileName);
  EXPECT_GT(RunLocalizePipeline(drive.Options()).run.frames.size(), 0u);
}

// Options a user gives that the acceptance rule does not read are refused, by field.
TEST(LocalizePipeline, GivenOptionsTheAcceptanceRuleIgnoresAreRefused) {
  LocalizationSessionOptions options;
  EXPECT_EQ(testing::OptionErrorPath([&] { options.CheckGiven({"min_verified"}); }), "min_verified");
  EXPECT_EQ(testing::OptionErrorPath([&] { options.CheckGiven({"first", "min_similarity"}); }), "min_similarity");
  options.CheckGiven({"min_link_share", "max_log10_nfa", "min_rival_ratio", "rival_max_log10_nfa"});
  options.localizer.acceptance = AcceptanceRule::kCounts;
  options.CheckGiven({"min_verified", "min_similarity"});
  EXPECT_EQ(testing::OptionErrorPath([&] { options.CheckGiven({"min_link_share"}); }), "min_link_share");
  EXPECT_EQ(testing::OptionErrorPath([&] { options.CheckGiven({"min_rival_ratio"}); }), "min_rival_ratio");
  EXPECT_EQ(testing::OptionErrorPath([&] { options.CheckGiven({"rival_max_log10_nfa"}); }), "rival_max_log10_nfa");
}

// An output that would overwrite the map is refused by its field before the map is read.
TEST(LocalizePipeline, OutputsAreCheckedFirstAndNamedByField) {
  Drive drive;
  LocalizePipelineOptions options = drive.Options();
  options.csv = (drive.map / "map.json").string();
  EXPECT_EQ(testing::OptionErrorPath([&] { RunLocalizePipeline(options); }), "csv");
  options.csv = (drive.tmp.path() / "same.txt").string();
  options.json = options.csv;
  EXPECT_EQ(testing::OptionErrorPath([&] { RunLocalizePipeline(options); }), "json");
  options = drive.Options();
  options.session.from = -3;
  EXPECT_EQ(testing::OptionErrorPath([&] { RunLocalizePipeline(options); }), "from");
  options = drive.Options();
  options.query.clear();
  EXPECT_EQ(testing::OptionErrorPath([&] { RunLocalizePipeline(options); }), "query");
}

}  // namespace
}  // namespace vmap
