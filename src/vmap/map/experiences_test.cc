#include "vmap/map/experiences.h"

#include <sys/stat.h>

#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "vmap/core/error.h"
#include "vmap/map/visual_map.h"
#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

struct MapWithViewFiles {
  ::vmap::testing::ScopedTempDir tmp;
  VisualMap map;
  MapWithViewFiles() {
    map.input.frame_size = cv::Size(64, 48);
    map.key_images.resize(3);
    fs::create_directories(tmp.path() / "experiences/1");
    cv::imwrite((tmp.path() / "experiences/1/000000.png").string(), cv::Mat(48, 64, CV_8UC1, cv::Scalar(9)));
    cv::imwrite((tmp.path() / "experiences/1/000002.png").string(), cv::Mat(48, 64, CV_8UC1, cv::Scalar(9)));
    cv::imwrite((tmp.path() / "experiences/1/small.png").string(), cv::Mat(24, 32, CV_8UC1, cv::Scalar(9)));
  }
  std::vector<Experience> Read(const json& value) const {
    return ExperiencesFromJson(value, map, tmp.path(), tmp.path() / "map.json");
  }
};

Experience Sample() {
  Experience e;
  e.id = 1;
  e.source = "winter.mp4";
  ExperienceView a;
  a.key = 0;
  a.image_file = "experiences/1/000000.png";
  a.frame_index = 4;
  a.source_index = 8;
  a.timestamp = 1.25;
  a.source_name = "frame_000008";
  a.heading_px = -12.5;
  a.num_verified = 40;
  ExperienceView b = a;
  b.key = 2;
  b.image_file = "experiences/1/000002.png";
  b.timestamp = -1.0;
  b.heading_px = 3.0;
  e.views = {a, b};
  return e;
}

TEST(Experiences, ReadBackAsWritten) {
  MapWithViewFiles map;
  const json written = ExperiencesToJson({Sample()});
  const std::vector<Experience> read = map.Read(json::parse(written.dump()));
  ASSERT_EQ(read.size(), 1u);
  EXPECT_EQ(read[0].id, 1);
  EXPECT_EQ(read[0].source, "winter.mp4");
  ASSERT_EQ(read[0].views.size(), 2u);
  EXPECT_EQ(read[0].views[0].frame_index, 4);
  EXPECT_EQ(read[0].views[0].source_index, 8);
  EXPECT_DOUBLE_EQ(read[0].views[0].timestamp, 1.25);
  EXPECT_DOUBLE_EQ(read[0].views[0].heading_px, -12.5);
  EXPECT_EQ(read[0].views[1].key, 2);
  EXPECT_DOUBLE_EQ(read[0].views[1].timestamp, -1.0);
  EXPECT_TRUE(written[0]["views"][1]["timestamp"].is_null());
  EXPECT_EQ(ExperiencesToJson(read), written);
}

// Each broken field is named in the message.
TEST(Experiences, RefusesMalformedEntriesNamingTheField) {
  MapWithViewFiles map;
  const json good = ExperiencesToJson({Sample()});
  const auto expect_refused = [&](json value, const std::string& field) {
    try {
      map.Read(value);
      ADD_FAILURE() << "accepted " << value.dump();
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  json bad = good;
  bad[0]["views"][0]["key"] = 3;  // the map has key images 0 to 2
  expect_refused(bad, "experiences[0].views[0].key");
  bad = good;
  bad[0]["views"][1]["key"] = 0;  // two views of one key image in one experience
  expect_refused(bad, "experiences[0].views[1].key");
  bad = good;
  bad[0]["id"] = 2;
  expect_refused(bad, "experiences[0].id");
  bad = good;
  bad[0]["views"][0]["heading_px"] = "left";
  expect_refused(bad, "experiences[0].views[0].heading_px");
  bad = good;
  bad[0]["views"][0]["heading_px"] = 1.7e308;  // a number, but no heading within the frame: damage
  expect_refused(bad, "experiences[0].views[0].heading_px' 1.7e+308 is beyond the frames' width of 64 px");
  bad = good;
  bad[0]["views"][0]["image"] = "../outside.png";
  expect_refused(bad, "points outside the map directory");
  bad = good;
  bad[0]["views"][0]["image"] = "experiences/1/missing.png";
  expect_refused(bad, "is missing");
  bad = good;
  bad[0]["views"][0]["image"] = "experiences/1/small.png";
  expect_refused(bad, "the map's frame size");
  bad = good;
  bad[0].erase("views");
  expect_refused(bad, "experiences[0].views");
  expect_refused(json::object(), "experiences");
}

// Issue 38: `info`, `report` and `route` read a map's experiences as `localize` does (ReadMap reads them), so a
// map whose views lead out of it, are FIFOs or are missing is refused by every command.
TEST(Experiences, EveryCommandRefusesAMapWithBrokenExperiences) {
  ::vmap::testing::ScopedTempDir tmp;
  ::vmap::testing::SyntheticOptions options;
  options.num_frames = 30;
  ::vmap::testing::WriteImageFolder(::vmap::testing::RenderSyntheticSequence(options), tmp.path() / "in");
  const fs::path map = tmp.path() / "map";
  std::string out;
  ASSERT_EQ(::vmap::testing::RunVmap(
                "build " + ::vmap::testing::Quote(tmp.path() / "in") + " -o " + ::vmap::testing::Quote(map), &out),
            0)
      << out;
  const std::string original = ::vmap::testing::ReadText(map / "map.json");
  const json document = json::parse(original);
  ASSERT_GE(document["key_images"].size(), 2u);
  fs::create_directories(map / "experiences/1");
  fs::copy_file(map / document["key_images"][0]["image"].get<std::string>(), map / "experiences/1/000000.png");
  fs::copy_file(map / document["key_images"][0]["image"].get<std::string>(), tmp.path() / "outside.png");
  fs::create_symlink(tmp.path() / "outside.png", map / "experiences/1/link.png");
  ASSERT_EQ(mkfifo((map / "experiences/1/fifo.png").c_str(), 0644), 0);
  const json view = {{"key", 0},
                     {"image", "experiences/1/000000.png"},
                     {"frame_index", 0},
                     {"source_index", 0},
                     {"timestamp", nullptr},
                     {"source_name", "0.png"},
                     {"heading_px", 0.0},
                     {"verified", 30}};
  const auto experience = [&](int id, json image, int key) {
    json v = view;
    v["image"] = std::move(image);
    v["key"] = key;
    return json{{"id", id}, {"source", "repeat"}, {"views", json::array({v})}};
  };
  const struct {
    json experiences;
    const char* expected;
  } cases[] = {
      {json::array({experience(1, "../outside.png", 0)}), "points outside the map directory"},
      {json::array({experience(1, (tmp.path() / "outside.png").string(), 0)}), "points outside the map directory"},
      {json::array({experience(1, "experiences/1/link.png", 0)}), "resolves outside"},
      {json::array({experience(1, "experiences/1/fifo.png", 0)}), "is not a regular file"},
      {json::array({experience(1, "experiences/1/missing.png", 0)}), "is missing"},
      {json::array({experience(1, "experiences/1/000000.png", 0), experience(1, "experiences/1/000000.png", 0)}),
       "experiences[1].id"},
      {json::array({experience(1, "experiences/1/000000.png", 999)}), "experiences[0].views[0].key"},
  };
  for (const auto& c : cases) {
    json broken = document;
    broken["experiences"] = c.experiences;
    std::ofstream(map / "map.json") << broken.dump(1);
    const std::vector<std::vector<std::string>> commands = {
        {"info", map.string()}, {"route", map.string(), "--from", "0", "--to", "1"}, {"report", map.string()}};
    for (const std::vector<std::string>& command : commands) {
      const ::vmap::testing::BoundedRun run = ::vmap::testing::RunVmapBounded(command, 30);
      EXPECT_EQ(run.status, 2) << command[0] << ": " << c.experiences.dump() << "\n" << run.output;
      EXPECT_NE(run.output.find(c.expected), std::string::npos) << command[0] << "\n" << run.output;
    }
  }
  std::ofstream(map / "map.json") << original;
  EXPECT_EQ(::vmap::testing::RunVmap("info " + ::vmap::testing::Quote(map), &out), 0) << out;
}

}  // namespace
}  // namespace vmap
