// Hostile maps: ReadMap refuses a missing, malformed or oversized map, or one whose files lead out of its folder,
// naming the problem and its file, before it reads more than the map's links reference.
#include <sys/stat.h>

#include <chrono>
#include <fstream>
#include <functional>
#include <limits>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "vmap/map/map_io.h"
#include "vmap/testing/map_io_test_util.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace fs = std::filesystem;
using testing::ReadMapError;
using testing::SmallMap;
using testing::WriteText;

namespace {

nlohmann::json ReadJson(const fs::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in);
}

}  // namespace

TEST(MapIo, MissingOrMalformedMapsNameTheProblem) {
  testing::ScopedTempDir tmp;
  EXPECT_NE(ReadMapError(tmp.path() / "nope").find("does not exist"), std::string::npos);
  EXPECT_NE(ReadMapError(tmp.path()).find("map.json is missing"), std::string::npos);
  // A sweep's folder (`vmap sweep --maps`): its maps, one level down, named.
  fs::create_directories(tmp.path() / "sweep/tau_0.50");
  WriteMapFiles(SmallMap(tmp.path() / "sweep/tau_0.50"), tmp.path() / "sweep/tau_0.50");
  EXPECT_NE(ReadMapError(tmp.path() / "sweep")
                .find("the maps are in its folders, e.g. '" + (tmp.path() / "sweep/tau_0.50").string() + "'"),
            std::string::npos)
      << ReadMapError(tmp.path() / "sweep");

  WriteMapFiles(SmallMap(tmp.path()), tmp.path());
  fs::remove(tmp.path() / "keys/9.png");
  EXPECT_NE(ReadMapError(tmp.path()).find("keys/9.png' is missing"), std::string::npos) << ReadMapError(tmp.path());

  WriteMapFiles(SmallMap(tmp.path()), tmp.path());
  fs::remove(tmp.path() / kCorrespondencesFileName);
  EXPECT_NE(ReadMapError(tmp.path()).find("correspondences.bin is missing"), std::string::npos);

  WriteText(tmp.path() / kMapFileName, "{not json");
  EXPECT_NE(ReadMapError(tmp.path()).find("not valid JSON"), std::string::npos);
}

TEST(MapIo, KeyImagePathsCannotLeaveTheMapDirectory) {
  testing::ScopedTempDir tmp;
  const fs::path map_dir = tmp.path() / "map";
  VisualMap map = SmallMap(map_dir);
  cv::imwrite((tmp.path() / "outside.png").string(), cv::Mat(4, 4, CV_8U));
  for (const std::string& bad : std::vector<std::string>{"../outside.png", (tmp.path() / "outside.png").string()}) {
    map.key_images[0].image_file = bad;
    WriteMapFiles(map, map_dir);
    EXPECT_NE(ReadMapError(map_dir).find("points outside the map directory"), std::string::npos) << bad;
  }
  // Nor lie where a report replaces everything.
  fs::create_directories(map_dir / "report");
  cv::imwrite((map_dir / "report/000000.png").string(), cv::Mat(4, 4, CV_8U));
  map.key_images[0].image_file = "report/000000.png";
  WriteMapFiles(map, map_dir);
  EXPECT_NE(ReadMapError(map_dir).find("lies in report/"), std::string::npos) << ReadMapError(map_dir);
}

TEST(MapIo, CorrespondenceRangesAreChecked) {
  testing::ScopedTempDir tmp;
  WriteMapFiles(SmallMap(tmp.path()), tmp.path());
  std::ifstream in(tmp.path() / kMapFileName);
  auto doc = nlohmann::json::parse(in);
  doc["links"][1]["correspondences"]["count"] = 1000;
  doc["links"][1]["tentative"] = 1000;
  WriteText(tmp.path() / kMapFileName, doc.dump());
  const std::string error = ReadMapError(tmp.path());
  EXPECT_NE(error.find("reference 1003 records"), std::string::npos) << error;
  EXPECT_NE(error.find("do not belong together"), std::string::npos) << error;
}

// Every field of map.json is checked for its type and range, and the message names the field.
TEST(MapIo, EveryFieldIsCheckedAndTheMessageNamesIt) {
  testing::ScopedTempDir tmp;
  WriteMapFiles(SmallMap(tmp.path()), tmp.path());
  const nlohmann::json good = ReadJson(tmp.path() / kMapFileName);
  using json = nlohmann::json;
  struct Case {
    std::function<void(json&)> change;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {[](json& d) { d["schema_version"] = "1"; }, "'schema_version' must be an integer"},
      {[](json& d) { d["format"] = "geojson"; }, "not a vmap map.json"},
      {[](json& d) { d["num_frames"] = 1e300; }, "'num_frames' must be an integer from 0 to 2147483647"},
      {[](json& d) { d["num_frames"] = 1ull << 40; }, "'num_frames' must be an integer"},
      {[](json& d) { d["num_frames"] = -20; }, "'num_frames' must be an integer"},
      {[](json& d) { d["quality"] = nullptr; }, "'quality' must be a finite number"},
      {[](json& d) { d["quality"] = 7.5; }, "'quality' must be a finite number from 0 to 1"},
      {[](json& d) { d["skipped_frames"] = -1; }, "'skipped_frames'"},
      {[](json& d) { d["options"] = json::array(); }, "'options' must be an object"},
      {[](json& d) { d["input"]["frame_size"] = {64}; }, "'input.frame_size' must be [width, height]"},
      {[](json& d) {
         d["input"]["frame_size"] = {64, -48};
       },
       "'input.frame_size[1]'"},
      {[](json& d) { d["input"]["format"] = "tape"; }, "'input.format' is not a known format"},
      {[](json& d) { d["input"]["fps"] = "fast"; }, "'input.fps'"},
      {[](json& d) { d["num_key_images"] = 7; }, "'num_key_images' does not match"},
      {[](json& d) { d["key_images"] = json::object(); }, "'key_images' must be a list"},
      {[](json& d) { d["key_images"][1] = 5; }, "'key_images[1]' must be an object"},
      {[](json& d) { d["key_images"][1]["frame_index"] = 20; },
       "'key_images[1].frame_index' must be an integer from 0 to 19"},
      {[](json& d) { d["key_images"][2]["frame_index"] = 9; }, "'key_images[2].frame_index' must be larger"},
      {[](json& d) { d["key_images"][0]["timestamp"] = "noon"; }, "'key_images[0].timestamp'"},
      {[](json& d) { d["key_images"][0]["image"] = 12; }, "'key_images[0].image' must be a string"},
      {[](json& d) { d["key_images"][0].erase("image"); }, "'key_images[0].image' is missing"},
      {[](json& d) { d["key_images"][2]["num_features"] = 1.5; }, "'key_images[2].num_features'"},
      {[](json& d) { d["links"] = "none"; }, "'links' must be a list"},
      {[](json& d) {
         d["links"].push_back(d["links"][0]);
         d["links"].push_back(d["links"][0]);
       },
       "'links' has more entries"},
      {[](json& d) { d["links"][0]["from"] = 5; }, "'links[0].from' must be an integer from 0 to 2"},
      {[](json& d) { d["links"][1]["to"] = 1; }, "'links[1].to' must name a key image after"},
      {[](json& d) { d["links"][1]["from"] = 0; },
       "'links[1]' joins key images 0 and 2; it must join key images 1 and 2"},
      {[](json& d) { d["links"].erase(1); },
       "'links' ends at key image 1 of the map's 3: key image 1 has no link to key image 2"},
      {[](json& d) { d["links"][0]["from_frame"] = 3; }, "'links[0].from_frame' is not the frame of key image 0"},
      {[](json& d) { d["links"][0]["below_tau"] = "no"; }, "'links[0].below_tau' must be true or false"},
      {[](json& d) { d["links"][0]["similarity"] = "high"; }, "'links[0].similarity'"},
      {[](json& d) { d["links"][0]["similarity"] = -0.5; }, "'links[0].similarity'"},
      {[](json& d) { d["links"][0]["verified"] = 4; }, "'links[0].verified' must be an integer from 0 to 3"},
      {[](json& d) { d["links"][0]["tentative"] = 1e10; }, "'links[0].tentative'"},
      {[](json& d) { d["links"][1]["F"] = {1, 2, 3, 4, 5, 6, 7, 8}; },
       "'links[1].F' must be null or a list of 9 finite numbers"},
      {[](json& d) { d["links"][1]["F"][4] = "x"; }, "'links[1].F' must be null or a list of 9 finite"},
      {[](json& d) { d["links"][1]["F"][4] = nullptr; }, "'links[1].F'"},
      {[](json& d) { d["links"][1]["F"] = "identity"; }, "'links[1].F'"},
      {[](json& d) { d["links"][0]["correspondences"]["offset"] = -1; }, "'links[0].correspondences.offset'"},
      {[](json& d) { d["links"][0]["correspondences"]["count"] = 1e12; }, "'links[0].correspondences.count'"},
      {[](json& d) { d["links"][0]["correspondences"]["count"] = 1; }, "'links[0].verified' is more than"},
      {[](json& d) { d["links"][0]["correspondences"]["offset"] = 1ull << 62; }, "'links[0].correspondences.offset'"},
      {[](json& d) { d["evaluations"]["frame"][1] = -3; }, "'evaluations.frame[1]' must be an integer from 0 to 19"},
      {[](json& d) { d["evaluations"]["similarity"][0] = 1e308; }, "'evaluations.similarity[0]'"},
      {[](json& d) { d["evaluations"]["verified"][0] = 11; },
       "'evaluations.verified[0]' must be an integer from 0 to 10"},
      {[](json& d) { d["evaluations"]["matched"][1] = 0; }, "'evaluations.matched[1]' must be true or false"},
      {[](json& d) { d["evaluations"]["matched"].push_back(true); }, "'evaluations' has columns of different lengths"},
      {[](json& d) { d["evaluations"].erase("key_frame"); }, "'evaluations.key_frame' is missing"},
      // Fields that contradict each other or describe nothing a camera makes.
      {[](json& d) { d["links"] = json::array(); }, "'links' is empty although the map has 3 key images"},
      {[](json& d) { d["key_images"][2]["image"] = d["key_images"][0]["image"]; },
       "'key_images[2].image' names the file of key_images[0]"},
      {[](json& d) {
         d["links"][1]["F"] = json::array({0, 0, 0, 0, 0, 0, 0, 0, 0});
       },
       "'links[1].F' is all zeros"},
      {[](json& d) { d["links"][1]["verified"] = 0; }, "'links[1].similarity' is more than 0 while 'verified' is 0"},
      {[](json& d) { d["links"][1]["correspondences"]["offset"] = d["links"][0]["correspondences"]["offset"]; },
       "overlaps the records of links[0]"},
      {[](json& d) {
         d["links"][0]["pose"] = nullptr;
         d["links"][0]["translation_known"] = true;
       },
       "links[0].translation_known is true without a pose"},
      {[](json& d) {
         d["input"]["frame_size"] = {0, 48};
       },
       "'input.frame_size' is 0x48 although the map has frames, which are never smaller than 32"},
      {[](json& d) {
         d["input"]["frame_size"] = {64, 0};
       },
       "'input.frame_size' is 64x0"},
      {[](json& d) {
         d["input"]["frame_size"] = {64, 8};
       },
       "'input.frame_size' is 64x8"},
      {[](json& d) {
         d["input"]["frame_size"] = {100000, 100000};
       },
       "which are never more than vmap's limit"},
      {[](json& d) { d.erase("input"); }, "'input' is missing"},
      {[](json& d) { d["input"]["path"] = std::string("in\0put", 6); }, "'input.path' holds a NUL character"},
      {[](json& d) { d["key_images"][1]["image"] = std::string("keys/1.png\0.jpg", 15); }, "NUL character"},
      {[](json& d) {
         d["input"]["camera"] = {{"model", "PINHOLE"}, {"width", 64}, {"height", 48}, {"params", {1e308, 50, 32, 24}}};
       },
       "beyond 10,000,000 pixels"},
      {[](json& d) {
         d["input"]["camera"] = {
             {"model", "PINHOLE"}, {"width", 1ull << 40}, {"height", 48}, {"params", {50, 50, 32, 24}}};
       },
       "has the size 1099511627776x48"},
  };
  for (const Case& c : cases) {
    json doc = good;
    c.change(doc);
    WriteText(tmp.path() / kMapFileName, doc.dump());
    const std::string error = ReadMapError(tmp.path());
    EXPECT_NE(error.find(c.expected), std::string::npos) << c.expected << "\n  got: " << error;
    EXPECT_NE(error.find(kMapFileName), std::string::npos) << error;
  }
  // Numbers beyond what JSON can hold, and nesting no map has.
  WriteText(tmp.path() / kMapFileName, R"({"format": "vmap-map", "schema_version": 1, "num_frames": 1e999})");
  EXPECT_NE(ReadMapError(tmp.path()).find("number too large"), std::string::npos) << ReadMapError(tmp.path());
  WriteText(tmp.path() / kMapFileName,
            R"({"format": "vmap-map", "options": )" + std::string(10000, '[') + std::string(10000, ']') + "}");
  EXPECT_NE(ReadMapError(tmp.path()).find("nested"), std::string::npos) << ReadMapError(tmp.path());
  // The untouched document still reads.
  WriteText(tmp.path() / kMapFileName, good.dump());
  EXPECT_EQ(ReadMapError(tmp.path()), "");
}

TEST(MapIo, FileSizesAreCheckedBeforeAnythingIsRead) {
  testing::ScopedTempDir tmp;
  WriteMapFiles(SmallMap(tmp.path()), tmp.path());
  const fs::path binary = tmp.path() / kCorrespondencesFileName;
  ASSERT_EQ(fs::file_size(binary), 6u * 16u);
  // A sparse file of 10 GB whose links cover 96 bytes: refused at once, without reading it.
  fs::resize_file(binary, 10ull << 30);
  const auto start = std::chrono::steady_clock::now();
  const std::string error = ReadMapError(tmp.path());
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
  EXPECT_NE(error.find("10737418240 bytes"), std::string::npos) << error;
  EXPECT_NE(error.find("96 bytes"), std::string::npos) << error;
  // One record too many or too few.
  for (const std::uintmax_t size : {7u * 16u, 5u * 16u, 6u * 16u + 3u}) {
    fs::resize_file(binary, size);
    EXPECT_NE(ReadMapError(tmp.path()).find("do not belong together"), std::string::npos) << size;
  }
  fs::resize_file(binary, 6u * 16u);
  EXPECT_EQ(ReadMapError(tmp.path()), "");
  // A map.json too large to be a map's is refused by its size too.
  EXPECT_GT(kMaxMapJsonBytes, 1000u);
}

TEST(MapIo, OnlyTheReferencedRecordsAreRead) {
  testing::ScopedTempDir tmp;
  VisualMap map = SmallMap(tmp.path());
  WriteMapFiles(map, tmp.path());
  // Records nobody references may hold anything: they are not read, so NaNs there do not matter; a NaN in a
  // referenced record is refused.
  auto doc = ReadJson(tmp.path() / kMapFileName);
  doc["links"][0]["correspondences"]["count"] = 2;
  doc["links"][0]["tentative"] = 2;
  WriteText(tmp.path() / kMapFileName, doc.dump());
  {
    std::fstream file(tmp.path() / kCorrespondencesFileName, std::ios::in | std::ios::out | std::ios::binary);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    file.seekp(2 * 16);  // link 0's third record, no longer referenced
    file.write(reinterpret_cast<const char*>(&nan), sizeof(nan));
  }
  const VisualMap back = ReadMap(tmp.path());
  EXPECT_EQ(back.links[0].correspondences.size(), 2u);
  EXPECT_EQ(back.links[1].correspondences[2].p1.x, 6.5f);
  doc["links"][0]["correspondences"]["count"] = 3;
  doc["links"][0]["tentative"] = 3;
  WriteText(tmp.path() / kMapFileName, doc.dump());
  EXPECT_NE(ReadMapError(tmp.path()).find("record 2 (links[0]) holds a coordinate that is not a finite number"),
            std::string::npos)
      << ReadMapError(tmp.path());
}

TEST(MapIo, NoFileIsReadThroughASymbolicLinkLeadingOut) {
  testing::ScopedTempDir tmp;
  const fs::path map_dir = tmp.path() / "map";
  WriteMapFiles(SmallMap(map_dir), map_dir);
  const fs::path outside = tmp.path() / "outside";
  fs::create_directories(outside);
  fs::copy(map_dir, outside, fs::copy_options::recursive);
  auto relink = [&](const std::string& name, const fs::path& target) {
    fs::remove_all(map_dir / name);
    fs::create_symlink(target, map_dir / name);
  };
  auto restore = [&](const std::string& name) {
    fs::remove_all(map_dir / name);
    fs::copy(outside / name, map_dir / name, fs::copy_options::recursive);
    ASSERT_EQ(ReadMapError(map_dir), "");
  };
  relink(kMapFileName, outside / kMapFileName);
  EXPECT_NE(ReadMapError(map_dir).find("resolves outside"), std::string::npos) << ReadMapError(map_dir);
  restore(kMapFileName);
  relink(kCorrespondencesFileName, "/dev/zero");
  EXPECT_NE(ReadMapError(map_dir).find("resolves outside the map directory"), std::string::npos)
      << ReadMapError(map_dir);
  restore(kCorrespondencesFileName);
  relink(kCorrespondencesFileName, outside / kCorrespondencesFileName);
  EXPECT_NE(ReadMapError(map_dir).find("resolves outside the map directory"), std::string::npos)
      << ReadMapError(map_dir);
  restore(kCorrespondencesFileName);
  relink("keys/9.png", outside / "keys/9.png");
  EXPECT_NE(ReadMapError(map_dir).find("key_images[1].image 'keys/9.png' resolves outside"), std::string::npos)
      << ReadMapError(map_dir);
  restore("keys/9.png");
  relink("keys", outside / "keys");
  EXPECT_NE(ReadMapError(map_dir).find("resolves outside"), std::string::npos) << ReadMapError(map_dir);
  restore("keys");
  // Not regular files: a FIFO would block a reader for ever, a folder is not a file.
  fs::remove(map_dir / kCorrespondencesFileName);
  ASSERT_EQ(mkfifo((map_dir / kCorrespondencesFileName).c_str(), 0600), 0);
  EXPECT_NE(ReadMapError(map_dir).find("is not a regular file"), std::string::npos) << ReadMapError(map_dir);
  restore(kCorrespondencesFileName);
  fs::remove(map_dir / kMapFileName);
  fs::create_directories(map_dir / kMapFileName);
  EXPECT_NE(ReadMapError(map_dir).find("is not a regular file"), std::string::npos) << ReadMapError(map_dir);
  restore(kMapFileName);
}

TEST(MapIo, KeyImagesMustBeThePngsOfTheMapsFrameSize) {
  testing::ScopedTempDir tmp;
  WriteMapFiles(SmallMap(tmp.path()), tmp.path());
  const fs::path key = tmp.path() / "keys/9.png";
  std::ofstream(key, std::ios::trunc) << "GIF89a";
  EXPECT_NE(ReadMapError(tmp.path()).find("'keys/9.png' is not a PNG or JPEG image"), std::string::npos)
      << ReadMapError(tmp.path());
  // The file is at fault, not map.json, which names it rightly.
  EXPECT_NE(ReadMapError(tmp.path()).find("has a damaged key image"), std::string::npos) << ReadMapError(tmp.path());
  EXPECT_EQ(ReadMapError(tmp.path()).find("malformed"), std::string::npos) << ReadMapError(tmp.path());
  cv::imwrite(key.string(), cv::Mat(10, 12, CV_8U, cv::Scalar(3)));
  EXPECT_NE(ReadMapError(tmp.path()).find("is 12x10, not the map's frame size 64x48"), std::string::npos)
      << ReadMapError(tmp.path());
  // A PNG of the right size cut short (a full disk): refused when the map is read, not when it is first decoded.
  cv::Mat noise(48, 64, CV_8U);
  cv::randu(noise, 0, 255);
  cv::imwrite(key.string(), noise);
  fs::resize_file(key, fs::file_size(key) / 2);
  EXPECT_NE(ReadMapError(tmp.path()).find("'keys/9.png' is a PNG cut short"), std::string::npos)
      << ReadMapError(tmp.path());
  // A PNG header announcing 40000 x 40000 pixels: refused from its 24 bytes, never decoded.
  const unsigned char header[] = {0x89, 'P', 'N', 'G',  '\r', '\n', 0x1A, '\n', 0,    0, 0, 13, 'I', 'H', 'D',
                                  'R',  0,   0,   0x9C, 0x40, 0,    0,    0x9C, 0x40, 8, 0, 0,  0,   0};
  std::ofstream(key, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(header), sizeof(header));
  EXPECT_NE(ReadMapError(tmp.path()).find("is 40000x40000"), std::string::npos) << ReadMapError(tmp.path());
}

TEST(MapIo, MalformedGeometryIsRefused) {
  testing::ScopedTempDir tmp;
  WriteMapFiles(SmallMap(tmp.path()), tmp.path());
  std::ifstream in(tmp.path() / kMapFileName);
  const auto original = nlohmann::json::parse(in);
  auto doc = original;
  doc["links"][0]["pose"] = {{"R", {2, 0, 0, 0, 1, 0, 0, 0, 1}}, {"t", {0, 0, 1}}, {"inliers", 3}};
  WriteText(tmp.path() / kMapFileName, doc.dump());
  EXPECT_NE(ReadMapError(tmp.path()).find("not a rotation matrix"), std::string::npos) << ReadMapError(tmp.path());
  doc = original;
  doc["links"][0]["pose"] = {{"R", {1, 0, 0, 0, 1, 0, 0, 0, 1}}, {"t", {0, 0, 3}}, {"inliers", 3}};
  WriteText(tmp.path() / kMapFileName, doc.dump());
  EXPECT_NE(ReadMapError(tmp.path()).find("not a unit vector"), std::string::npos) << ReadMapError(tmp.path());
  doc = original;
  doc["input"]["camera"] = {{"model", "PINHOLE"}, {"params", {500, 500, 320}}, {"width", 64}, {"height", 48}};
  WriteText(tmp.path() / kMapFileName, doc.dump());
  EXPECT_NE(ReadMapError(tmp.path()).find("input.camera"), std::string::npos) << ReadMapError(tmp.path());
  doc = original;
  doc["links"][0]["parallax_px"] = "far";
  WriteText(tmp.path() / kMapFileName, doc.dump());
  EXPECT_NE(ReadMapError(tmp.path()).find("parallax_px"), std::string::npos) << ReadMapError(tmp.path());
  doc = original;
  doc["links"][1]["planar"] = "yes";
  WriteText(tmp.path() / kMapFileName, doc.dump());
  EXPECT_NE(ReadMapError(tmp.path()).find("links[1]"), std::string::npos) << ReadMapError(tmp.path());
  doc = original;
  doc["input"]["camera"] = {{"model", "PINHOLE"}, {"params", {500, 500, 32, 24}}, {"width", "wide"}};
  WriteText(tmp.path() / kMapFileName, doc.dump());
  EXPECT_NE(ReadMapError(tmp.path()).find("input.camera"), std::string::npos) << ReadMapError(tmp.path());
}

}  // namespace vmap
