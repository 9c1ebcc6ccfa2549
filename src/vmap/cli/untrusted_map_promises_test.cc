// Promise 2 of docs/promises.md, tested on the binary with several maps: reading an untrusted map never leaves its
// folder, reads only what the links reference, checks every field, quickly and with little memory.

#include <sys/stat.h>

#include <fstream>
#include <functional>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "vmap/map/map_io.h"
#include "vmap/testing/promises_test_util.h"
#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace fs = std::filesystem;
using testing::BuildMapWithBinary;
using testing::ReadText;
using testing::WriteSyntheticInput;

TEST(Promises, UntrustedMapsAreRefusedQuicklyWithLittleMemory) {
  testing::ScopedTempDir tmp;
  WriteSyntheticInput(tmp.path() / "in", 8);
  BuildMapWithBinary(tmp.path() / "in", tmp.path() / "good");
  ASSERT_GT(ReadMap(tmp.path() / "good").links.size(), 0u);
  auto variant = [&](const std::string& name, const std::function<void(const fs::path&)>& change) {
    const fs::path dir = tmp.path() / name;
    fs::copy(tmp.path() / "good", dir, fs::copy_options::recursive);
    change(dir);
    return dir;
  };
  struct Case {
    fs::path map;
    std::string expected;
    long max_rss_mb = 400;
  };
  const std::vector<Case> cases = {
      {variant("sparse", [](const fs::path& d) { fs::resize_file(d / kCorrespondencesFileName, 10ull << 30); }),
       "10737418240 bytes"},
      {variant("zero",
               [](const fs::path& d) {
                 fs::remove(d / kCorrespondencesFileName);
                 fs::create_symlink("/dev/zero", d / kCorrespondencesFileName);
               }),
       "resolves outside the map directory"},
      {variant("fifo",
               [](const fs::path& d) {
                 fs::remove(d / kCorrespondencesFileName);
                 mkfifo((d / kCorrespondencesFileName).c_str(), 0600);
               }),
       "is not a regular file"},
      {variant("bad_f",
               [](const fs::path& d) {
                 auto doc = nlohmann::json::parse(ReadText(d / kMapFileName));
                 doc["links"][0]["F"] = {1, 2, 3};
                 std::ofstream(d / kMapFileName) << doc.dump();
               }),
       "'links[0].F' must be null or a list of 9 finite numbers"},
      {variant("huge_number",
               [](const fs::path& d) {
                 std::string text = ReadText(d / kMapFileName);
                 const size_t at = text.find("\"num_frames\": ") + 14;
                 text.replace(at, text.find_first_of(",\n", at) - at, "1e999");
                 std::ofstream(d / kMapFileName) << text;
               }),
       "number too large"},
      {variant("many_values",
               [](const fs::path& d) {
                 // Few bytes a value: 9 million of them in 18 MB, refused by their count before they are held.
                 auto doc = nlohmann::json::parse(ReadText(d / kMapFileName));
                 std::string text = doc.dump();
                 std::string padding = "\"padding\": [0";
                 padding.reserve(18u << 20);
                 for (int i = 0; i < 9000000; ++i) padding += ",0";
                 text.insert(1, padding + "], ");
                 std::ofstream(d / kMapFileName) << text;
               }),
       "holds more than",
       // The values parsed before the count is reached (8,388,608, some 55 bytes each in nlohmann-json): 470 MB
       // measured, where all of them took 1.26 GB and 150 million numbers aborted vmap.
       600},
  };
  for (const Case& c : cases) {
    const std::vector<std::vector<std::string>> commands = {
        {"info", c.map.string()},
        {"report", c.map.string()},
        {"draw", c.map.string(), "--link", "0", "-o", (tmp.path() / "fig.png").string()}};
    for (const std::vector<std::string>& command : commands) {
      const testing::BoundedRun run = testing::RunVmapBounded(command, 120.0);
      EXPECT_EQ(run.status, 2) << c.map << " " << command[0];
      EXPECT_EQ(run.output.find("vmap: error: "), 0u) << run.output;
      EXPECT_NE(run.output.find(c.expected), std::string::npos) << c.map << " " << command[0] << ": " << run.output;
      // CPU time, not wall time: "quickly" is about the work a hostile map can make vmap do, which the load of
      // other processes on a shared machine does not change (wall time doubles when two test jobs share a core).
      EXPECT_LT(run.cpu_seconds, 10.0) << c.map;
      EXPECT_LT(run.max_rss_bytes, c.max_rss_mb << 20)
          << c.map << " " << command[0];  // far below the 10 GB of the sparse file
    }
    EXPECT_FALSE(fs::exists(c.map / "report.html")) << c.map;
  }
  EXPECT_FALSE(fs::exists(tmp.path() / "fig.png"));
}

// The peak memory the test above bounds is the run's own: a test process that grew before (a whole vmap_tests run
// holds what earlier tests left in its heap) does not count in it, as it does in the child posix_spawn starts.
TEST(Promises, TheMemoryOfARunIsItsOwn) {
  std::vector<char> held(768u << 20);
  for (size_t i = 0; i < held.size(); i += 4096) held[i] = static_cast<char>(i);  // resident, not just reserved
  const testing::BoundedRun run = testing::RunVmapBounded({"--version"}, 60.0);
  EXPECT_EQ(run.status, 0) << run.output;
  EXPECT_GT(run.max_rss_bytes, 0);
  EXPECT_LT(run.max_rss_bytes, 384l << 20) << "this process holds " << (held.size() >> 20) << " MB";
  EXPECT_EQ(run.output.find("vmap-testing-usage"), std::string::npos)
      << run.output;  // the measure's line is not output
}

}  // namespace vmap
