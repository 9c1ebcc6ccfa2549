#include "vmap/map/experiences.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "vmap/core/error.h"
#include "vmap/map/visual_map.h"
#include "vmap/testing/scoped_temp_dir.h"

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

}  // namespace
}  // namespace vmap
