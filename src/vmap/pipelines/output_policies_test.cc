#include "vmap/pipelines/output_policies.h"

#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "vmap/core/error.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace fs = std::filesystem;

// A map's own files are never an output's, whichever command writes it: `vmap simulate --json MAP/map.json` replaced
// the map's map.json (and --json MAP/keys/000000.png its key image), since simulate's inputs do not name the map.
TEST(OutputPolicies, NoOutputReplacesAFileOfAMapItLiesIn) {
  testing::ScopedTempDir tmp;
  const fs::path map = tmp.path() / "map";
  fs::create_directories(map / "keys");
  std::ofstream(map / "map.json") << R"({"format": "vmap-map", "schema_version": 1})";
  std::ofstream(map / "keys" / "000000.png") << "a key image";
  for (const fs::path& own : {map / "map.json", map / "keys" / "000000.png", map / "teach_odometry.csv"}) {
    try {
      CheckOutputs({{own, "json"}}, {});
      ADD_FAILURE() << "accepted " << own;
    } catch (const OptionError& error) {
      EXPECT_EQ(error.path(), "json");
      EXPECT_NE(std::string(error.what()).find("the map's"), std::string::npos) << error.what();
    }
  }
  // Another name in the map's folder is a run's output, as before; so is map.json in a folder that is no map.
  EXPECT_NO_THROW(CheckOutputs({{map / "run.json", "json"}}, {}));
  fs::create_directory(tmp.path() / "other");
  std::ofstream(tmp.path() / "other" / "map.json") << R"({"a": 1})";
  EXPECT_NO_THROW(CheckOutputs({{tmp.path() / "other" / "map.json", "json"}}, {}));
}

}  // namespace vmap
