#include "vmap/map/map_io.h"

#include <sys/stat.h>

#include <chrono>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "vmap/core/error.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace fs = std::filesystem;

namespace {

VisualMap SmallMap(const fs::path& directory) {
  VisualMap map;
  map.input.path = "video.mp4";
  map.input.format = SourceFormat::kVideo;
  map.input.frame_size = {64, 48};
  map.options_json = R"({"tau": 0.5, "quality_mean": "arithmetic"})";
  map.num_frames = 20;
  fs::create_directories(directory / "keys");
  for (int f : {0, 9, 19}) {
    KeyImage k;
    k.frame_index = f;
    k.source_index = f;
    k.timestamp = f / 30.0;
    k.source_name = "frame_" + std::to_string(f);
    k.image_file = "keys/" + std::to_string(f) + ".png";
    cv::imwrite((directory / k.image_file).string(), cv::Mat(48, 64, CV_8U, cv::Scalar(f)));
    map.key_images.push_back(k);
  }
  for (int i = 0; i < 2; ++i) {
    Link l;
    l.from_key = i;
    l.to_key = i + 1;
    l.num_tentative = 3;
    l.num_verified = 2;
    l.similarity = 2.0 / 3.0;
    l.has_fundamental = true;
    l.F = cv::Matx33d(0, -1e-3, 0.1 * i, 1e-3, 0, -0.2, -0.1, 0.2, 1);
    for (int c = 0; c < 3; ++c) l.correspondences.push_back({{1.5f * c, 2.f + i}, {3.25f * c, 4.f}});
    map.links.push_back(l);
  }
  map.evaluations = {{0, 1, 0.9, 10, 9, true}, {0, 2, 0.0, 3, 0, false}};
  map.quality = 0.42;
  return map;
}

void WriteText(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

std::string ErrorOf(const fs::path& directory) {
  try {
    ReadMap(directory);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(MapIo, RoundTripKeepsEverything) {
  testing::ScopedTempDir tmp;
  const VisualMap map = SmallMap(tmp.path());
  WriteMapFiles(map, tmp.path());
  const VisualMap back = ReadMap(tmp.path());
  ASSERT_EQ(back.key_images.size(), 3u);
  EXPECT_EQ(back.key_images[1].frame_index, 9);
  EXPECT_NEAR(back.key_images[1].timestamp, 0.3, 1e-12);
  ASSERT_EQ(back.links.size(), 2u);
  EXPECT_EQ(back.links[1].correspondences.size(), 3u);
  EXPECT_EQ(back.links[1].correspondences[2].p1.x, 6.5f);
  EXPECT_EQ(back.links[1].correspondences[0].p0.y, 3.f);
  EXPECT_EQ(back.links[1].F(0, 2), 0.1);
  EXPECT_EQ(back.evaluations.size(), 2u);
  EXPECT_FALSE(back.evaluations[1].matched);
  EXPECT_EQ(back.num_frames, 20);
  EXPECT_DOUBLE_EQ(back.quality, 0.42);
  // Correspondences are 16 bytes each, as documented.
  EXPECT_EQ(fs::file_size(tmp.path() / kCorrespondencesFileName), 6u * 16u);
}

TEST(MapIo, MissingOrMalformedMapsNameTheProblem) {
  testing::ScopedTempDir tmp;
  EXPECT_NE(ErrorOf(tmp.path() / "nope").find("does not exist"), std::string::npos);
  EXPECT_NE(ErrorOf(tmp.path()).find("map.json is missing"), std::string::npos);

  WriteMapFiles(SmallMap(tmp.path()), tmp.path());
  fs::remove(tmp.path() / "keys/9.png");
  EXPECT_NE(ErrorOf(tmp.path()).find("keys/9.png' is missing"), std::string::npos) << ErrorOf(tmp.path());

  WriteMapFiles(SmallMap(tmp.path()), tmp.path());
  fs::remove(tmp.path() / kCorrespondencesFileName);
  EXPECT_NE(ErrorOf(tmp.path()).find("correspondences.bin is missing"), std::string::npos);

  WriteText(tmp.path() / kMapFileName, "{not json");
  EXPECT_NE(ErrorOf(tmp.path()).find("not valid JSON"), std::string::npos);
}

TEST(MapIo, KeyImagePathsCannotLeaveTheMapDirectory) {
  testing::ScopedTempDir tmp;
  const fs::path map_dir = tmp.path() / "map";
  VisualMap map = SmallMap(map_dir);
  cv::imwrite((tmp.path() / "outside.png").string(), cv::Mat(4, 4, CV_8U));
  for (const std::string& bad : std::vector<std::string>{"../outside.png", (tmp.path() / "outside.png").string()}) {
    map.key_images[0].image_file = bad;
    WriteMapFiles(map, map_dir);
    EXPECT_NE(ErrorOf(map_dir).find("points outside the map directory"), std::string::npos) << bad;
  }
}

TEST(MapIo, CorrespondenceRangesAreChecked) {
  testing::ScopedTempDir tmp;
  WriteMapFiles(SmallMap(tmp.path()), tmp.path());
  std::ifstream in(tmp.path() / kMapFileName);
  auto doc = nlohmann::json::parse(in);
  doc["links"][1]["correspondences"]["count"] = 1000;
  doc["links"][1]["tentative"] = 1000;
  WriteText(tmp.path() / kMapFileName, doc.dump());
  const std::string error = ErrorOf(tmp.path());
  EXPECT_NE(error.find("reference 1003 records"), std::string::npos) << error;
  EXPECT_NE(error.find("do not belong together"), std::string::npos) << error;
}

namespace {

nlohmann::json ReadJson(const fs::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in);
}

TEST(MapIo, ReadKeyImageDecodesTheKeyImagesReadMapChecked) {
  testing::ScopedTempDir tmp;
  WriteMapFiles(SmallMap(tmp.path()), tmp.path());
  const VisualMap map = ReadMap(tmp.path());
  const cv::Mat color = ReadKeyImage(tmp.path(), map.key_images[1]);
  EXPECT_EQ(color.type(), CV_8UC3);
  EXPECT_EQ(color.size(), cv::Size(64, 48));
  const cv::Mat gray = ReadKeyImage(tmp.path(), map.key_images[1], /*grayscale=*/true);
  ASSERT_EQ(gray.type(), CV_8UC1);
  EXPECT_EQ(gray.at<uchar>(10, 10), 9) << "key image of frame 9 is filled with 9";

  // The map changed on disk after ReadMap: each problem is named with its file and the fix.
  auto ErrorOf = [](const auto& read) -> std::string {
    try {
      read();
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  KeyImage escaping = map.key_images[0];
  escaping.image_file = "../outside.png";
  EXPECT_NE(ErrorOf([&] { ReadKeyImage(tmp.path(), escaping); }).find("points outside the map directory"),
            std::string::npos);
  std::ofstream(tmp.path() / "keys/9.png", std::ios::trunc) << "not a png";
  const std::string undecodable = ErrorOf([&] { ReadKeyImage(tmp.path(), map.key_images[1]); });
  EXPECT_NE(undecodable.find("keys/9.png' cannot be decoded"), std::string::npos) << undecodable;
  EXPECT_NE(undecodable.find("rebuild the map"), std::string::npos) << undecodable;
  fs::remove(tmp.path() / "keys/9.png");
  const std::string missing = ErrorOf([&] { KeyImageFile(tmp.path(), map.key_images[1]); });
  EXPECT_NE(missing.find("keys/9.png' is missing"), std::string::npos) << missing;
}

}  // namespace

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
    const std::string error = ErrorOf(tmp.path());
    EXPECT_NE(error.find(c.expected), std::string::npos) << c.expected << "\n  got: " << error;
    EXPECT_NE(error.find(kMapFileName), std::string::npos) << error;
  }
  // Numbers beyond what JSON can hold, and nesting no map has.
  WriteText(tmp.path() / kMapFileName, R"({"format": "vmap-map", "schema_version": 1, "num_frames": 1e999})");
  EXPECT_NE(ErrorOf(tmp.path()).find("number too large"), std::string::npos) << ErrorOf(tmp.path());
  WriteText(tmp.path() / kMapFileName,
            R"({"format": "vmap-map", "options": )" + std::string(10000, '[') + std::string(10000, ']') + "}");
  EXPECT_NE(ErrorOf(tmp.path()).find("nested"), std::string::npos) << ErrorOf(tmp.path());
  // The untouched document still reads.
  WriteText(tmp.path() / kMapFileName, good.dump());
  EXPECT_EQ(ErrorOf(tmp.path()), "");
}

TEST(MapIo, FileSizesAreCheckedBeforeAnythingIsRead) {
  testing::ScopedTempDir tmp;
  WriteMapFiles(SmallMap(tmp.path()), tmp.path());
  const fs::path binary = tmp.path() / kCorrespondencesFileName;
  ASSERT_EQ(fs::file_size(binary), 6u * 16u);
  // A sparse file of 10 GB whose links cover 96 bytes: refused at once, without reading it.
  fs::resize_file(binary, 10ull << 30);
  const auto start = std::chrono::steady_clock::now();
  const std::string error = ErrorOf(tmp.path());
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
  EXPECT_NE(error.find("10737418240 bytes"), std::string::npos) << error;
  EXPECT_NE(error.find("96 bytes"), std::string::npos) << error;
  // One record too many or too few.
  for (const std::uintmax_t size : {7u * 16u, 5u * 16u, 6u * 16u + 3u}) {
    fs::resize_file(binary, size);
    EXPECT_NE(ErrorOf(tmp.path()).find("do not belong together"), std::string::npos) << size;
  }
  fs::resize_file(binary, 6u * 16u);
  EXPECT_EQ(ErrorOf(tmp.path()), "");
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
  EXPECT_NE(ErrorOf(tmp.path()).find("record 2 (links[0]) holds a coordinate that is not a finite number"),
            std::string::npos)
      << ErrorOf(tmp.path());
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
    ASSERT_EQ(ErrorOf(map_dir), "");
  };
  relink(kMapFileName, outside / kMapFileName);
  EXPECT_NE(ErrorOf(map_dir).find("resolves outside"), std::string::npos) << ErrorOf(map_dir);
  restore(kMapFileName);
  relink(kCorrespondencesFileName, "/dev/zero");
  EXPECT_NE(ErrorOf(map_dir).find("resolves outside the map directory"), std::string::npos) << ErrorOf(map_dir);
  restore(kCorrespondencesFileName);
  relink(kCorrespondencesFileName, outside / kCorrespondencesFileName);
  EXPECT_NE(ErrorOf(map_dir).find("resolves outside the map directory"), std::string::npos) << ErrorOf(map_dir);
  restore(kCorrespondencesFileName);
  relink("keys/9.png", outside / "keys/9.png");
  EXPECT_NE(ErrorOf(map_dir).find("key_images[1].image 'keys/9.png' resolves outside"), std::string::npos)
      << ErrorOf(map_dir);
  restore("keys/9.png");
  relink("keys", outside / "keys");
  EXPECT_NE(ErrorOf(map_dir).find("resolves outside"), std::string::npos) << ErrorOf(map_dir);
  restore("keys");
  // Not regular files: a FIFO would block a reader for ever, a folder is not a file.
  fs::remove(map_dir / kCorrespondencesFileName);
  ASSERT_EQ(mkfifo((map_dir / kCorrespondencesFileName).c_str(), 0600), 0);
  EXPECT_NE(ErrorOf(map_dir).find("is not a regular file"), std::string::npos) << ErrorOf(map_dir);
  restore(kCorrespondencesFileName);
  fs::remove(map_dir / kMapFileName);
  fs::create_directories(map_dir / kMapFileName);
  EXPECT_NE(ErrorOf(map_dir).find("is not a regular file"), std::string::npos) << ErrorOf(map_dir);
  restore(kMapFileName);
}

TEST(MapIo, KeyImagesMustBeThePngsOfTheMapsFrameSize) {
  testing::ScopedTempDir tmp;
  WriteMapFiles(SmallMap(tmp.path()), tmp.path());
  const fs::path key = tmp.path() / "keys/9.png";
  std::ofstream(key, std::ios::trunc) << "GIF89a";
  EXPECT_NE(ErrorOf(tmp.path()).find("'keys/9.png' is not a PNG or JPEG image"), std::string::npos)
      << ErrorOf(tmp.path());
  cv::imwrite(key.string(), cv::Mat(10, 12, CV_8U, cv::Scalar(3)));
  EXPECT_NE(ErrorOf(tmp.path()).find("is 12x10, not the map's frame size 64x48"), std::string::npos)
      << ErrorOf(tmp.path());
  // A PNG header announcing 40000 x 40000 pixels: refused from its 24 bytes, never decoded.
  const unsigned char header[] = {0x89, 'P', 'N', 'G',  '\r', '\n', 0x1A, '\n', 0,    0, 0, 13, 'I', 'H', 'D',
                                  'R',  0,   0,   0x9C, 0x40, 0,    0,    0x9C, 0x40, 8, 0, 0,  0,   0};
  std::ofstream(key, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(header), sizeof(header));
  EXPECT_NE(ErrorOf(tmp.path()).find("is 40000x40000"), std::string::npos) << ErrorOf(tmp.path());
}

TEST(MapIo, FileNamesThatAreNotUtf8RoundTrip) {
  testing::ScopedTempDir tmp;
  VisualMap map = SmallMap(tmp.path());
  map.input.path = "/data/\xFFrun%1";
  map.key_images[1].source_name = "caf\xE9 9.png";
  WriteMapFiles(map, tmp.path());
  std::ifstream in(tmp.path() / kMapFileName);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("/data/%FFrun%251"), std::string::npos);
  EXPECT_NE(text.find("caf%E9 9.png"), std::string::npos);
  const VisualMap back = ReadMap(tmp.path());
  EXPECT_EQ(back.input.path, map.input.path);
  EXPECT_EQ(back.key_images[1].source_name, map.key_images[1].source_name);
  EXPECT_EQ(back.key_images[0].source_name, "frame_0");
}

TEST(MapIo, OwnershipNeedsAVmapMapJson) {
  testing::ScopedTempDir tmp;
  WriteMapFiles(SmallMap(tmp.path() / "map"), tmp.path() / "map");
  EXPECT_EQ(WhyNotAVmapMap(tmp.path() / "map"), "");
  struct Case {
    std::string map_json, expected;
  };
  const std::vector<Case> cases = {
      {"", "it has no map.json"},
      {R"({"type": "FeatureCollection"})", "no \"format\": \"vmap-map\""},
      {R"({"format": "vmap-map"})", "no integer \"schema_version\""},
      {R"({"format": "vmap-map", "schema_version": "1"})", "no integer \"schema_version\""},
      {R"([1, 2])", "no \"format\""},
      {"{oops", "not valid JSON"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    const fs::path dir = tmp.path() / std::to_string(i);
    fs::create_directories(dir / "src");
    if (!cases[i].map_json.empty()) WriteText(dir / kMapFileName, cases[i].map_json);
    EXPECT_NE(WhyNotAVmapMap(dir).find(cases[i].expected), std::string::npos) << WhyNotAVmapMap(dir);
  }
  // A map.json that is a link to a real map's elsewhere proves nothing.
  fs::create_directories(tmp.path() / "linked");
  fs::create_symlink(tmp.path() / "map" / kMapFileName, tmp.path() / "linked" / kMapFileName);
  EXPECT_NE(WhyNotAVmapMap(tmp.path() / "linked"), "");
}

TEST(MapIo, CameraAndLinkGeometryRoundTrip) {
  testing::ScopedTempDir tmp;
  VisualMap map = SmallMap(tmp.path());
  Camera camera = Camera::Make(50.5, 51.0, 31.5, 23.5, {-0.1, 0.01, 0.001, -0.002}, {64, 48});
  camera.origin = "intrinsics.txt";
  map.input.camera = camera;
  Link& link = map.links[1];
  link.below_tau = true;
  link.has_pose = true;
  cv::Rodrigues(cv::Vec3d(0.01, -0.2, 0.03), link.R);
  link.t = cv::normalize(cv::Vec3d(0.3, -0.1, -0.9));
  link.pose_inliers = 2;
  link.translation_sigma_deg = 7.5;
  link.translation_rival_cost_gap = 2.25;
  link.translation_known = false;
  link.parallax = 12.25;
  link.parallax_without_rotation = true;
  link.homography_share = 0.5;
  link.planar = false;
  WriteMapFiles(map, tmp.path());
  const VisualMap back = ReadMap(tmp.path());
  ASSERT_TRUE(back.input.camera);
  EXPECT_EQ(back.input.camera->model, CameraModel::kOpenCV);
  EXPECT_EQ(back.input.camera->K(), camera.K());
  EXPECT_EQ(back.input.camera->distortion(), camera.distortion());
  EXPECT_EQ(back.input.camera->size, cv::Size(64, 48));
  EXPECT_EQ(back.input.camera->origin, "intrinsics.txt");
  EXPECT_FALSE(back.links[0].below_tau);
  EXPECT_FALSE(back.links[0].has_pose);
  EXPECT_LT(back.links[0].parallax, 0);  // not computed
  const Link& l = back.links[1];
  EXPECT_TRUE(l.below_tau);
  ASSERT_TRUE(l.has_pose);
  EXPECT_LT(cv::norm(l.R - link.R), 1e-12);
  EXPECT_LT(cv::norm(l.t - link.t), 1e-12);
  EXPECT_EQ(l.pose_inliers, 2);
  EXPECT_DOUBLE_EQ(l.translation_sigma_deg, 7.5);
  EXPECT_DOUBLE_EQ(l.translation_rival_cost_gap, 2.25);
  EXPECT_LT(back.links[0].translation_rival_cost_gap, 0);  // none
  EXPECT_FALSE(l.translation_known);
  EXPECT_LT(back.links[0].translation_sigma_deg, 0);  // no pose: not computed
  EXPECT_DOUBLE_EQ(l.parallax, 12.25);
  EXPECT_TRUE(l.parallax_without_rotation);
  EXPECT_DOUBLE_EQ(l.homography_share, 0.5);
  // The document says what the numbers mean, and the COLMAP model name.
  std::ifstream in(tmp.path() / kMapFileName);
  const auto doc = nlohmann::json::parse(in);
  EXPECT_EQ(doc["schema_version"], 2);
  EXPECT_EQ(doc["input"]["camera"]["model"], "OPENCV");
  EXPECT_EQ(doc["input"]["camera"]["params"].size(), 8u);
  EXPECT_NE(doc["conventions"]["pose"].get<std::string>().find("X_to = R X_from + t"), std::string::npos);
  EXPECT_FALSE(doc["links"][0].contains("broken"));
}

TEST(MapIo, ReadsSchemaVersionOneMapsWithBrokenLinks) {
  testing::ScopedTempDir tmp;
  WriteMapFiles(SmallMap(tmp.path()), tmp.path());
  std::ifstream in(tmp.path() / kMapFileName);
  auto doc = nlohmann::json::parse(in);
  // A map as vmap wrote it before links had a geometry: `broken`, no camera, no pose.
  doc["schema_version"] = 1;
  doc["input"].erase("camera");
  doc.erase("conventions");
  for (auto& link : doc["links"]) {
    for (const char* key :
         {"below_tau", "pose", "parallax_px", "parallax_rotation_removed", "homography_share", "planar"}) {
      link.erase(key);
    }
  }
  doc["links"][0]["broken"] = true;
  doc["links"][1]["broken"] = false;
  WriteText(tmp.path() / kMapFileName, doc.dump());
  const VisualMap map = ReadMap(tmp.path());
  EXPECT_TRUE(map.links[0].below_tau);
  EXPECT_FALSE(map.links[1].below_tau);
  EXPECT_FALSE(map.links[0].has_pose);
  EXPECT_FALSE(map.input.camera);
}

// Maps written before links said how well their translation is known: a pose reads as known (what such a map
// claimed), its sigma as not computed.
TEST(MapIo, ReadsMapsWithoutTheTranslationFields) {
  testing::ScopedTempDir tmp;
  VisualMap map = SmallMap(tmp.path());
  map.links[1].has_pose = true;
  map.links[1].t = cv::Vec3d(0, 0, -1);
  WriteMapFiles(map, tmp.path());
  std::ifstream in(tmp.path() / kMapFileName);
  auto doc = nlohmann::json::parse(in);
  for (auto& link : doc["links"]) {
    link.erase("translation_sigma_deg");
    link.erase("translation_known");
    link.erase("translation_rival_cost_gap");
  }
  WriteText(tmp.path() / kMapFileName, doc.dump());
  const VisualMap back = ReadMap(tmp.path());
  EXPECT_FALSE(back.links[0].translation_known);
  EXPECT_TRUE(back.links[1].translation_known);
  EXPECT_LT(back.links[1].translation_sigma_deg, 0);
  EXPECT_LT(back.links[1].translation_rival_cost_gap, 0);
}

TEST(MapIo, MalformedGeometryIsRefused) {
  testing::ScopedTempDir tmp;
  WriteMapFiles(SmallMap(tmp.path()), tmp.path());
  std::ifstream in(tmp.path() / kMapFileName);
  const auto original = nlohmann::json::parse(in);
  auto doc = original;
  doc["links"][0]["pose"] = {{"R", {2, 0, 0, 0, 1, 0, 0, 0, 1}}, {"t", {0, 0, 1}}, {"inliers", 3}};
  WriteText(tmp.path() / kMapFileName, doc.dump());
  EXPECT_NE(ErrorOf(tmp.path()).find("not a rotation matrix"), std::string::npos) << ErrorOf(tmp.path());
  doc = original;
  doc["links"][0]["pose"] = {{"R", {1, 0, 0, 0, 1, 0, 0, 0, 1}}, {"t", {0, 0, 3}}, {"inliers", 3}};
  WriteText(tmp.path() / kMapFileName, doc.dump());
  EXPECT_NE(ErrorOf(tmp.path()).find("not a unit vector"), std::string::npos) << ErrorOf(tmp.path());
  doc = original;
  doc["input"]["camera"] = {{"model", "PINHOLE"}, {"params", {500, 500, 320}}, {"width", 64}, {"height", 48}};
  WriteText(tmp.path() / kMapFileName, doc.dump());
  EXPECT_NE(ErrorOf(tmp.path()).find("input.camera"), std::string::npos) << ErrorOf(tmp.path());
  doc = original;
  doc["links"][0]["parallax_px"] = "far";
  WriteText(tmp.path() / kMapFileName, doc.dump());
  EXPECT_NE(ErrorOf(tmp.path()).find("parallax_px"), std::string::npos) << ErrorOf(tmp.path());
  doc = original;
  doc["links"][1]["planar"] = "yes";
  WriteText(tmp.path() / kMapFileName, doc.dump());
  EXPECT_NE(ErrorOf(tmp.path()).find("links[1]"), std::string::npos) << ErrorOf(tmp.path());
  doc = original;
  doc["input"]["camera"] = {{"model", "PINHOLE"}, {"params", {500, 500, 32, 24}}, {"width", "wide"}};
  WriteText(tmp.path() / kMapFileName, doc.dump());
  EXPECT_NE(ErrorOf(tmp.path()).find("input.camera"), std::string::npos) << ErrorOf(tmp.path());
}

// The sizes ReadMap checks come from the headers alone, for both kinds of key image.
TEST(MapIo, KeyImageFileSizeReadsPngAndJpegHeaders) {
  testing::ScopedTempDir tmp;
  const cv::Mat image(37, 53, CV_8UC3, cv::Scalar(10, 200, 30));
  ASSERT_TRUE(cv::imwrite((tmp.path() / "a.png").string(), image));
  ASSERT_TRUE(cv::imwrite((tmp.path() / "a.jpg").string(), image));
  ASSERT_TRUE(cv::imwrite((tmp.path() / "p.jpg").string(), image, {cv::IMWRITE_JPEG_PROGRESSIVE, 1}));
  EXPECT_EQ(KeyImageFileSize(tmp.path() / "a.png"), cv::Size(53, 37));
  EXPECT_EQ(KeyImageFileSize(tmp.path() / "a.jpg"), cv::Size(53, 37));
  EXPECT_EQ(KeyImageFileSize(tmp.path() / "p.jpg"), cv::Size(53, 37));
  WriteText(tmp.path() / "text.jpg", "not an image");
  EXPECT_FALSE(KeyImageFileSize(tmp.path() / "text.jpg").has_value());
  EXPECT_FALSE(KeyImageFileSize(tmp.path() / "missing.png").has_value());
}

}  // namespace vmap

namespace vmap {

// map.json is streamed (WriteMapJson) so that a long build's evaluations never sit in memory as one JSON
// document; its text must stay what nlohmann's dump(1) of the whole document gives (MapToJson).
TEST(MapIo, StreamedMapJsonIsTheWholeDocumentsDump) {
  testing::ScopedTempDir tmp;
  VisualMap map = SmallMap(tmp.path());
  map.evaluations.push_back({9, 10, 1.0, 7, 7, true});
  map.evaluations.push_back({9, 11, 1e-300, 4, 1, true});
  map.evaluations.push_back({9, 12, 0.1 + 0.2, 40, 12, true});
  for (bool with_evaluations : {true, false}) {
    VisualMap variant = map;
    if (!with_evaluations) variant.evaluations.clear();
    std::ostringstream streamed;
    WriteMapJson(streamed, variant);
    EXPECT_EQ(streamed.str(), MapToJson(variant) + "\n") << with_evaluations;
  }
  // The evaluations from elsewhere (a build's file), with the map's own list empty: the same text.
  VisualMap without = map;
  without.evaluations.clear();
  std::ostringstream from_source;
  WriteMapJson(from_source, without, [&map](const std::function<void(const Evaluation&)>& fn) {
    for (const Evaluation& e : map.evaluations) fn(e);
  });
  EXPECT_EQ(from_source.str(), MapToJson(map) + "\n");
}

TEST(MapIo, CoverageIsWrittenOnlyWhenKnownAndReadBack) {
  testing::ScopedTempDir tmp;
  VisualMap map = SmallMap(tmp.path());
  WriteMapFiles(map, tmp.path());
  EXPECT_FALSE(ReadMap(tmp.path()).coverage);
  EXPECT_FALSE(nlohmann::json::parse(std::ifstream(tmp.path() / kMapFileName)).contains("coverage"));
  map.coverage = Coverage{20, 100, 119, CoverageEnd::kInterrupted};
  WriteMapFiles(map, tmp.path());
  const VisualMap back = ReadMap(tmp.path());
  ASSERT_TRUE(back.coverage);
  EXPECT_EQ(back.coverage->num_frames, 20);
  EXPECT_EQ(back.coverage->first_source_index, 100);
  EXPECT_EQ(back.coverage->last_source_index, 119);
  EXPECT_EQ(back.coverage->end, CoverageEnd::kInterrupted);
  // More frames covered than the map has is malformed.
  auto doc = nlohmann::json::parse(std::ifstream(tmp.path() / kMapFileName));
  doc["coverage"]["frames"] = 21;
  WriteText(tmp.path() / kMapFileName, doc.dump());
  EXPECT_NE(ErrorOf(tmp.path()).find("'coverage.frames' must be an integer from 0 to 20"), std::string::npos)
      << ErrorOf(tmp.path());
}

}  // namespace vmap
