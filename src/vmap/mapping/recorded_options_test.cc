// map.json's "options" written from the options structs and read back into them.

#include "vmap/mapping/recorded_options.h"

#include <set>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "vmap/core/error.h"
#include "vmap/map/map_io.h"
#include "vmap/testing/option_error.h"
#include "vmap/testing/report_test_util.h"
#include "vmap/testing/scoped_temp_dir.h"

namespace vmap {
namespace {

// Every recorded field away from its default.
RecordedOptions Unusual() {
  RecordedOptions options;
  options.matcher_json = R"({"type": "orb", "num_features": 1000})";
  MapBuilderOptions& builder = options.builder;
  builder.key_images.tau = 0.35;
  builder.key_images.similarity = SimilarityMode::kFeatureRatio;
  builder.key_images.final_key = false;
  builder.key_images.min_key_displacement = 2.5;
  builder.verifier.method = VerifierMethod::kAccurate;
  builder.verifier.threshold = 0.75;
  builder.verifier.confidence = 0.99;
  builder.verifier.max_iterations = 5000;
  builder.verifier.seed = 7;
  builder.verifier.min_matches = 12;
  builder.verifier.max_samples_to_reject = 2500;
  builder.quality_mean = QualityMean::kHarmonic;
  builder.exhaustive = true;
  builder.key_search = KeySearch::kSequential;
  builder.search_window = 64;
  builder.link_analysis.pose.method = PoseMethod::kFromFundamental;
  builder.link_analysis.pose.threshold = 2.0;
  builder.link_analysis.pose.use_all_matches = false;
  builder.link_analysis.pose.confidence = 0.9;
  builder.link_analysis.pose.max_iterations = 300;
  builder.link_analysis.pose.seed = 4;
  builder.link_analysis.homography.threshold = 3.0;
  builder.link_analysis.homography.min_share = 0.8;
  builder.link_analysis.translation.max_sigma_deg = 7.5;
  builder.link_analysis.translation.min_parallax_px = 1.5;
  options.source.format = SourceFormat::kTum;
  options.source.first = 10;
  options.source.last = 99;
  options.source.stride = 3;
  options.source.resize = "640x480";
  options.source.strict = true;
  options.source.camera = "525,525,320,240";
  return options;
}

TEST(RecordedOptions, EveryRecordedFieldReadsBackAsWritten) {
  const RecordedOptions written = Unusual();
  const RecordedOptions read = RecordedOptionsFromJson(ToJson(written).dump(), "options");
  EXPECT_EQ(read.matcher_type, "orb");
  EXPECT_EQ(nlohmann::json::parse(read.matcher_json), nlohmann::json::parse(written.matcher_json));
  const MapBuilderOptions& a = written.builder;
  const MapBuilderOptions& b = read.builder;
  EXPECT_EQ(b.key_images.tau, a.key_images.tau);
  EXPECT_EQ(b.key_images.similarity, a.key_images.similarity);
  EXPECT_EQ(b.key_images.final_key, a.key_images.final_key);
  EXPECT_EQ(b.key_images.min_key_displacement, a.key_images.min_key_displacement);
  EXPECT_EQ(b.verifier.method, a.verifier.method);
  EXPECT_EQ(b.verifier.threshold, a.verifier.threshold);
  EXPECT_EQ(b.verifier.confidence, a.verifier.confidence);
  EXPECT_EQ(b.verifier.max_iterations, a.verifier.max_iterations);
  EXPECT_EQ(b.verifier.seed, a.verifier.seed);
  EXPECT_EQ(b.verifier.min_matches, a.verifier.min_matches);
  EXPECT_EQ(b.verifier.max_samples_to_reject, a.verifier.max_samples_to_reject);
  EXPECT_EQ(b.quality_mean, a.quality_mean);
  EXPECT_EQ(b.exhaustive, a.exhaustive);
  EXPECT_EQ(b.key_search, a.key_search);
  EXPECT_EQ(b.search_window, a.search_window);
  const PoseOptions& pa = a.link_analysis.pose;
  const PoseOptions& pb = b.link_analysis.pose;
  EXPECT_EQ(pb.method, pa.method);
  EXPECT_EQ(pb.threshold, pa.threshold);
  EXPECT_EQ(pb.use_all_matches, pa.use_all_matches);
  EXPECT_EQ(pb.confidence, pa.confidence);
  EXPECT_EQ(pb.max_iterations, pa.max_iterations);
  EXPECT_EQ(pb.seed, pa.seed);
  EXPECT_EQ(b.link_analysis.homography.threshold, a.link_analysis.homography.threshold);
  EXPECT_EQ(b.link_analysis.homography.min_share, a.link_analysis.homography.min_share);
  EXPECT_EQ(b.link_analysis.translation.max_sigma_deg, a.link_analysis.translation.max_sigma_deg);
  EXPECT_EQ(b.link_analysis.translation.min_parallax_px, a.link_analysis.translation.min_parallax_px);
  EXPECT_EQ(read.source.format, written.source.format);
  EXPECT_EQ(read.source.first, written.source.first);
  EXPECT_EQ(read.source.last, written.source.last);
  EXPECT_EQ(read.source.stride, written.source.stride);
  EXPECT_EQ(read.source.resize, written.source.resize);
  EXPECT_EQ(read.source.strict, written.source.strict);
  EXPECT_EQ(read.source.camera, written.source.camera);
  EXPECT_EQ(ToJson(read), ToJson(written));  // and so the same record again
}

// The layout users' scripts read (docs/map-format.md): the builder's fields at the top level, the input's
// camera "input" when it came with the input, the search that ran (auto resolved).
TEST(RecordedOptions, KeepsMapJsonsLayout) {
  const nlohmann::json record = ToJson(RecordedOptions{});
  std::set<std::string> keys;
  for (const auto& item : record.items()) keys.insert(item.key());
  EXPECT_EQ(keys, (std::set<std::string>{"pose_check_features", "exhaustive", "final_key", "homography", "matcher",
                                         "min_key_displacement", "pose", "quality_mean", "search", "search_window",
                                         "similarity", "source", "tau", "translation", "verifier"}));
  EXPECT_EQ(record["pose_check_features"], 2000);
  EXPECT_EQ(record["source"]["camera"], "input");
  EXPECT_EQ(record["search"], "sequential");
  EXPECT_EQ(record["pose"]["matches"], "all");
  EXPECT_EQ(record["verifier"]["method"], "magsac");
  EXPECT_EQ(record["tau"], 0.5);
  EXPECT_EQ(RecordedOptionsFromJson(record.dump(), "options").source.camera, "");
}

TEST(RecordedOptions, AnOlderRecordKeepsTheDefaultsOfWhatItLacks) {
  const RecordedOptions read = RecordedOptionsFromJson(R"({"tau": 0.6, "matcher": {"name": "orb"}})", "options");
  EXPECT_EQ(read.builder.key_images.tau, 0.6);
  EXPECT_EQ(read.matcher_type, "");
  EXPECT_EQ(read.builder.quality_mean, QualityMean::kArithmetic);
  EXPECT_EQ(read.builder.link_analysis.pose.method, PoseOptions().method);
  EXPECT_EQ(read.source.stride, 1);
}

TEST(RecordedOptions, AMalformedRecordNamesTheField) {
  auto error = [](const std::string& text) {
    return testing::InputErrorMessage([&] { RecordedOptionsFromJson(text, "map 'm/map.json': options"); });
  };
  EXPECT_EQ(error(R"({"quality_mean": "median"})"),
            "map 'm/map.json': options.quality_mean is 'median', which this vmap does not know (it knows arithmetic "
            "or harmonic)");
  EXPECT_EQ(error(R"({"verifier": {"threshold": "0.5"}})"),
            "map 'm/map.json': options.verifier.threshold must be a number (it is string)");
  EXPECT_EQ(error(R"({"pose": {"matches": "some"}})"),
            "map 'm/map.json': options.pose.matches is 'some', which this vmap does not know (it knows all or "
            "verified)");
  EXPECT_EQ(error(R"({"source": []})"), "map 'm/map.json': options.source must be a JSON object (it is array)");
  EXPECT_EQ(error("[1]"), "map 'm/map.json': options is not a JSON object (it is array)");
  // Values no build takes: the map's error, by the record's key, where localize once blamed its own map_tau.
  EXPECT_NE(error(R"({"tau": 7})").find("map 'm/map.json': options.tau 7 is outside (0, 1]"), std::string::npos)
      << error(R"({"tau": 7})");
  EXPECT_NE(error(R"({"tau": 7})").find("rebuild the map with `vmap build`"), std::string::npos);
  EXPECT_NE(error(R"({"source": {"stride": 0}})").find("map 'm/map.json': options.source.stride 0 is less than 1"),
            std::string::npos)
      << error(R"({"source": {"stride": 0}})");
  EXPECT_EQ(error("{"), "map 'm/map.json': options is not valid JSON");
}

// A map is read with its options typed, once; the record stays as written, fields this vmap does not know
// included.
TEST(RecordedOptions, AMapIsReadWithItsOptionsTyped) {
  testing::ScopedTempDir directory;
  report_test::SyntheticMapOptions options;
  options.tau = 0.6;
  VisualMap map = report_test::WriteSyntheticMap(directory.path() / "m", options);
  const RecordedMap read = ReadRecordedMap(directory.path() / "m");
  EXPECT_EQ(read.options.builder.key_images.tau, 0.6);
  EXPECT_EQ(read.options.builder.quality_mean, QualityMean::kArithmetic);
  EXPECT_EQ(read.map.key_images.size(), map.key_images.size());
  EXPECT_EQ(nlohmann::json::parse(read.map.options_json)["matcher"]["features"], 2000);

  map.options_json = R"({"quality_mean": "median"})";
  WriteMapFiles(map, directory.path() / "m");
  EXPECT_EQ(testing::InputErrorMessage([&] { ReadRecordedMap(directory.path() / "m"); }),
            "map '" + (directory.path() / "m" / "map.json").string() +
                "': options.quality_mean is 'median', which this vmap does not know (it knows arithmetic or "
                "harmonic)");
}

}  // namespace
}  // namespace vmap
