#include "vmap/pipelines/report_pipeline.h"

#include <atomic>
#include <chrono>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "vmap/core/directory_lock.h"
#include "vmap/map/map_io.h"
#include "vmap/report/html_report.h"
#include "vmap/testing/report_test_util.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace {
namespace fs = std::filesystem;

std::set<std::string> Listing(const fs::path& directory) {
  std::set<std::string> names;
  for (const auto& entry : fs::recursive_directory_iterator(directory)) {
    names.insert(fs::relative(entry.path(), directory).string());
  }
  return names;
}

// `vmap report MAP` writes into the map: a rebuild replacing it meanwhile (a writer holding the map's lock) is waited
// for, so that the page put in the map describes the map it lies in.
TEST(ReportPipeline, AMapsReportWaitsForAWriterOfTheMapAndWritesNothingMeanwhile) {
  testing::ScopedTempDir temp;
  const fs::path map = temp.path() / "map";
  report_test::WriteSyntheticMap(map);
  const std::set<std::string> before = Listing(map);
  std::optional<DirectoryWriteLock> rebuild(std::in_place, map, "the map");  // another writer, in effect
  std::atomic<bool> done{false};
  std::thread report([&] {
    ReportPipelineOptions options;
    options.target = map.string();
    options.map_report.route_video = false;
    RunReportPipeline(options);
    done = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_FALSE(done);
  EXPECT_EQ(Listing(map), before);
  rebuild.reset();
  report.join();
  EXPECT_TRUE(fs::is_regular_file(map / kReportFileName));
}

}  // namespace
}  // namespace vmap
