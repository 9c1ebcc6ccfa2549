// `vmap build REPEAT --add-experience-to MAP` interrupted (SIGINT) or killed (SIGKILL) while it localizes, and
// run twice at once, on a map and runs rendered by the test: the map is left as it was, or gains both
// experiences; nothing of an interrupted run stays, and what a killed one left goes with the next add.

#include <signal.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "vmap/map/map_io.h"
#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace {
namespace fs = std::filesystem;
using ::vmap::testing::Quote;

// A teach run and a repeat run (the same drive) as image folders, and a map of the teach run.
struct Route {
  ::vmap::testing::ScopedTempDir tmp;
  fs::path teach = tmp.path() / "teach", repeat = tmp.path() / "repeat", map = tmp.path() / "map";
  Route() {
    ::vmap::testing::SyntheticOptions options;
    options.num_frames = 60;
    const auto sequence = ::vmap::testing::RenderSyntheticSequence(options);
    ::vmap::testing::WriteImageFolder(sequence, teach);
    ::vmap::testing::WriteImageFolder(sequence, repeat);
    std::string out;
    EXPECT_EQ(::vmap::testing::RunVmap("build " + Quote(teach) + " -o " + Quote(map), &out), 0) << out;
  }
  std::vector<std::string> Add() const { return {"build", repeat.string(), "--add-experience-to", map.string()}; }
};

std::map<std::string, std::string> Snapshot(const fs::path& directory) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(directory)) {
    std::ifstream in(entry.path(), std::ios::binary);
    std::stringstream bytes;
    if (entry.is_regular_file()) bytes << in.rdbuf();
    files[fs::relative(entry.path(), directory).string()] = entry.is_regular_file() ? bytes.str() : "<dir>";
  }
  return files;
}

bool HasEntryStartingWith(const fs::path& directory, const std::string& prefix) {
  for (const auto& entry : fs::directory_iterator(directory)) {
    if (entry.path().filename().string().rfind(prefix, 0) == 0) return true;
  }
  return false;
}

// Waits (at most 60 s) until the add has begun writing its views into the map.
bool WaitForViews(const fs::path& map, const ::vmap::testing::BackgroundVmap& run) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline && run.Running()) {
    if (HasEntryStartingWith(map, ".experiences.partial-")) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return false;
}

TEST(AddExperienceSignals, AnInterruptedAddLeavesTheMapAsItWas) {
  Route route;
  const auto before = Snapshot(route.map);
  ::vmap::testing::BackgroundVmap run(route.Add(), route.tmp.path() / "log");
  ASSERT_TRUE(WaitForViews(route.map, run)) << "the add never began writing its views";
  run.Signal(SIGINT);
  EXPECT_EQ(run.Wait(), 128 + SIGINT);
  EXPECT_EQ(Snapshot(route.map), before);  // no experiences/, no temporary, map.json as it was
}

TEST(AddExperienceSignals, WhatAKilledAddLeftGoesWithTheNextOne) {
  Route route;
  {
    ::vmap::testing::BackgroundVmap run(route.Add(), route.tmp.path() / "log");
    ASSERT_TRUE(WaitForViews(route.map, run));
    run.Signal(SIGKILL);
    EXPECT_EQ(run.Wait(), 128 + SIGKILL);
  }
  EXPECT_FALSE(fs::exists(route.map / "experiences"));
  EXPECT_NO_THROW(ReadMap(route.map));
  const ::vmap::testing::BoundedRun again = ::vmap::testing::RunVmapBounded(route.Add(), 120);
  ASSERT_EQ(again.status, 0) << again.output;
  EXPECT_FALSE(HasEntryStartingWith(route.map, ".experiences.partial-"));
  EXPECT_EQ(ReadMap(route.map).experiences.size(), 1u);
}

TEST(AddExperienceSignals, TwoAddsAtOnceBothLand) {
  Route route;
  ::vmap::testing::BackgroundVmap first(route.Add(), route.tmp.path() / "log1");
  ::vmap::testing::BackgroundVmap second(route.Add(), route.tmp.path() / "log2");
  EXPECT_EQ(first.Wait(), 0);
  EXPECT_EQ(second.Wait(), 0);
  const VisualMap map = ReadMap(route.map);
  ASSERT_EQ(map.experiences.size(), 2u);
  std::string out;
  EXPECT_EQ(::vmap::testing::RunVmap("localize " + Quote(route.map) + " " + Quote(route.repeat) + " -q", &out), 0)
      << out;
}

}  // namespace
}  // namespace vmap
