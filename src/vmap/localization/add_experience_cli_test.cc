// `vmap build REPEAT --add-experience-to MAP` and `vmap localize` of a map with experiences, end to end on the
// michigan seasonal images: one session a map of its 5 places, another session added as an experience.

#include <unistd.h>

#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/shared_data.h"

namespace vmap {
namespace {
namespace fs = std::filesystem;
using ::vmap::testing::Quote;
using ::vmap::testing::RunVmap;

// A folder of session `session`'s 5 images (symbolic links), in place order.
fs::path SessionFolder(const fs::path& parent, int session) {
  const fs::path folder = parent / ("session" + std::to_string(session));
  fs::create_directories(folder);
  for (int place = 1; place <= 5; ++place) {
    char name[16];
    std::snprintf(name, sizeof(name), "%02d%02d.png", session, place);
    fs::create_symlink(fs::path(::vmap::testing::SharedDir()) / "data/michigan_seasons/images" / name, folder / name);
  }
  return folder;
}

std::string ReadText(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(AddExperienceCli, AddsASessionAndLocalizeReportsTheExperienceUsed) {
  SKIP_WITHOUT_SHARED();
  ::vmap::testing::ScopedTempDir tmp;
  const fs::path map = tmp.path() / "map";
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(SessionFolder(tmp.path(), 1)) + " -o " + Quote(map) + " -q", &out), 0) << out;
  const fs::path csv_before = tmp.path() / "before.csv";
  const fs::path query = SessionFolder(tmp.path(), 3);
  ASSERT_EQ(RunVmap("localize " + Quote(map) + " " + Quote(query) + " --csv " + Quote(csv_before) + " -q", &out), 0)
      << out;
  EXPECT_EQ(ReadText(csv_before).find("experience"), std::string::npos);  // a map without: columns as before

  // Refused before anything is written: another matcher, an output folder, a folder that is not a map.
  const std::string json_before = ReadText(map / "map.json");
  const fs::path repeat = SessionFolder(tmp.path(), 2);
  EXPECT_EQ(RunVmap("build " + Quote(repeat) + " --add-experience-to " + Quote(map) + " --matcher aliked", &out), 2);
  EXPECT_NE(out.find("--matcher orb"), std::string::npos) << out;
  EXPECT_EQ(
      RunVmap("build " + Quote(repeat) + " --add-experience-to " + Quote(map) + " -o " + Quote(tmp.path() / "other"),
              &out),
      2);
  EXPECT_NE(out.find("drop -o"), std::string::npos) << out;
  EXPECT_EQ(RunVmap("build " + Quote(repeat) + " --add-experience-to " + Quote(repeat), &out), 2);
  EXPECT_NE(out.find("vmap: error:"), std::string::npos) << out;
  EXPECT_EQ(ReadText(map / "map.json"), json_before);
  EXPECT_FALSE(fs::exists(map / "experiences"));

  EXPECT_EQ(RunVmap("build " + Quote(repeat) + " -o " + Quote(tmp.path() / "other") + " --acceptance chance", &out), 2);
  EXPECT_NE(out.find("go with --add-experience-to"), std::string::npos) << out;
  // Across seasons ORB's verified sets are small: they are accepted by how unlikely they are by chance.
  ASSERT_EQ(RunVmap("build " + Quote(repeat) + " --add-experience-to " + Quote(map) + " --acceptance chance", &out), 0)
      << out;
  EXPECT_NE(out.find("experience      1"), std::string::npos) << out;
  const nlohmann::json doc = nlohmann::json::parse(ReadText(map / "map.json"));
  ASSERT_EQ(doc["experiences"].size(), 1u);
  EXPECT_GE(doc["experiences"][0]["views"].size(), 1u);
  for (const auto& view : doc["experiences"][0]["views"]) {
    EXPECT_TRUE(fs::is_regular_file(map / view["image"].get<std::string>()));
  }

  const fs::path csv = tmp.path() / "after.csv", json = tmp.path() / "after.json";
  ASSERT_EQ(RunVmap("localize " + Quote(map) + " " + Quote(query) + " --csv " + Quote(csv) + " --json " + Quote(json) +
                        " --acceptance chance -q",
                    &out),
            0)
      << out;
  const std::string header = ReadText(csv).substr(0, ReadText(csv).find('\n'));
  EXPECT_NE(header.find(",experience,next_experience"), std::string::npos) << header;
  const nlohmann::json run = nlohmann::json::parse(ReadText(json));
  for (const auto& frame : run["frames"]) {
    ASSERT_TRUE(frame.contains("experience"));
    if (frame["key"].get<int>() >= 0) {
      EXPECT_TRUE(frame["experience"] == 0 || frame["experience"] == 1);
    }
  }
}

// A report shows what S was measured against: a frame compared best with an experience's view is drawn beside that
// view, and named so; the map's report lists its experiences.
TEST(AddExperienceCli, ReportsShowTheViewComparedAndListTheExperiences) {
  SKIP_WITHOUT_SHARED();
  ::vmap::testing::ScopedTempDir tmp;
  const fs::path map = tmp.path() / "map";
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(SessionFolder(tmp.path(), 1)) + " -o " + Quote(map) + " -q", &out), 0) << out;
  const fs::path repeat = SessionFolder(tmp.path(), 2);
  ASSERT_EQ(RunVmap("build " + Quote(repeat) + " --add-experience-to " + Quote(map) + " --acceptance chance", &out), 0)
      << out;
  // The repeat run itself: its frames are the views.
  const fs::path json = tmp.path() / "run.json", report = tmp.path() / "report";
  ASSERT_EQ(RunVmap("localize " + Quote(map) + " " + Quote(repeat) + " --json " + Quote(json) + " --report " +
                        Quote(report) + " --acceptance chance -q",
                    &out),
            0)
      << out;
  const nlohmann::json run = nlohmann::json::parse(ReadText(json));
  const std::string page = ReadText(report / "report.html");
  int from_views = 0;
  for (const auto& frame : run["frames"]) {
    if (frame["key"].get<int>() < 0 || frame["experience"] != 1) continue;
    ++from_views;
    const std::string caption = "key " + std::to_string(frame["key"].get<int>()) + " (experience 1) (S = ";
    EXPECT_NE(page.find(caption), std::string::npos) << caption << "\n" << page;
  }
  EXPECT_GE(from_views, 1) << run.dump();

  ASSERT_EQ(RunVmap("report " + Quote(map), &out), 0) << out;
  const std::string map_page = ReadText(map / "report.html");
  EXPECT_NE(map_page.find("<h2>Experiences (1)</h2>"), std::string::npos);
  EXPECT_NE(map_page.find(repeat.string()), std::string::npos);
}

// A map and its experience are replaced together, and never by surprise: an add while a build started before it is
// replacing the map is refused (the build's map, put in place after, lacked it: the add had said it was added); a
// build over a map with experiences says that it drops them; a killed add's temporary is no user file the rebuilt
// map keeps.
TEST(AddExperienceCli, AnExperienceIsNeverAddedToAMapABuildIsReplacing) {
  SKIP_WITHOUT_SHARED();
  ::vmap::testing::ScopedTempDir tmp("experience_rebuilt");
  const fs::path map = tmp.path() / "map", repeat = SessionFolder(tmp.path(), 2);
  std::string out;
  ASSERT_EQ(RunVmap("build " + Quote(SessionFolder(tmp.path(), 1)) + " -o " + Quote(map) + " -q", &out), 0) << out;
  // A build of this process (alive) writing the map's replacement beside it.
  const fs::path building = tmp.path() / (".map.partial-" + std::to_string(getpid()) + "-0");
  fs::create_directories(building);
  EXPECT_EQ(RunVmap("build " + Quote(repeat) + " --add-experience-to " + Quote(map), &out), 2) << out;
  EXPECT_NE(out.find("is being rebuilt by vmap process " + std::to_string(getpid())), std::string::npos) << out;
  fs::remove(building);
  // A flag that sets how a map is built is refused, not taken and ignored: the run is matched with the map's options.
  EXPECT_EQ(
      RunVmap("build " + Quote(repeat) + " --add-experience-to " + Quote(map) + " --orb-features 2000 --tau 0.3", &out),
      2)
      << out;
  EXPECT_NE(out.find("--orb-features, --tau set how a map is built"), std::string::npos) << out;
  ASSERT_EQ(RunVmap("build " + Quote(repeat) + " --add-experience-to " + Quote(map) + " --threads 1 -q", &out), 0)
      << out;
  ASSERT_TRUE(fs::is_directory(map / "experiences/1"));
  ASSERT_EQ(RunVmap("info " + Quote(map), &out), 0) << out;
  EXPECT_NE(out.find("experiences     1 ("), std::string::npos) << out;
  // Left by an add that was killed (no such process).
  const fs::path dead = map / ".experiences.partial-999999999-0";
  fs::create_directories(dead);
  ASSERT_EQ(RunVmap("build " + Quote(SessionFolder(tmp.path(), 3)) + " -o " + Quote(map), &out), 0) << out;
  EXPECT_NE(out.find("holds 1 experience(s) of other runs, which the new map replaces"), std::string::npos) << out;
  EXPECT_EQ(out.find(".experiences.partial"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(dead));
  EXPECT_FALSE(fs::exists(map / "experiences"));
}

}  // namespace
}  // namespace vmap
