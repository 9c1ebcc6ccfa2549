#include "vmap/features/matcher_registry.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "vmap/core/error.h"
#include "vmap/features/matcher_options_json.h"
#include "vmap/features/matcher_plugin.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/shared_data.h"
#include "vmap/testing/synthetic_scene.h"

namespace vmap {
namespace {

std::set<std::string> RegisteredNames() {
  std::set<std::string> names;
  for (const auto& model : MatcherModels()) names.insert(model.name);
  return names;
}

// The models of this build register from their folders (linked through vmap_matcher_models).
TEST(MatcherRegistry, HoldsOrbAndTheDeepModels) {
  EXPECT_EQ(RegisteredNames(), (std::set<std::string>{"orb", "loftr", "xfeat", "aliked"}));
  EXPECT_EQ(MatcherModels().front().name, "orb");  // built-in first: the default and the paper's
  for (const auto& model : MatcherModels()) {
    EXPECT_FALSE(model.summary.empty()) << model.name;
    EXPECT_EQ(model.needs_torch, model.name != "orb") << model.name;
    EXPECT_EQ(static_cast<bool>(model.create), !model.needs_torch) << model.name;
    EXPECT_STREQ(model.default_options()->model(), model.name.c_str());
  }
}

TEST(MatcherRegistry, AnUnknownNameListsTheRegisteredOnes) {
  for (const auto& call :
       std::vector<std::function<void()>>{[] { FindMatcherModel("sift"); }, [] { DefaultTau("sift"); },
                                          [] {
                                            MatcherOptions options;
                                            options.type = "sift";
                                            CreateMatcher(options);
                                          }}) {
    try {
      call();
      ADD_FAILURE() << "no error for an unknown matcher";
    } catch (const InputError& error) {
      const std::string message = error.what();
      EXPECT_TRUE(message.find("unknown matcher 'sift'") != std::string::npos ||
                  message.find("matcher 'sift' is unknown") != std::string::npos)
          << message;
      for (const auto& name : RegisteredNames()) EXPECT_NE(message.find(name), std::string::npos) << message;
    }
  }
}

TEST(MatcherRegistry, DefaultTauIsEachModelsOwn) {
  // The values the sweeps of docs/measurements/deep-matchers.md chose (matcher_registry.h, DefaultTau).
  EXPECT_DOUBLE_EQ(DefaultTau("orb"), 0.5);
  EXPECT_DOUBLE_EQ(DefaultTau("xfeat"), 0.4);
  EXPECT_DOUBLE_EQ(DefaultTau("aliked"), 0.7);
  EXPECT_DOUBLE_EQ(DefaultTau("loftr"), 0.5);
}

// Moves every field away from its default, so that a field the JSON drops shows.
class ChangeEveryField final : public OptionFieldVisitor {
 protected:
  void OnField(const OptionField&, int& value) override { value += 3; }
  void OnField(const OptionField&, double& value) override { value += 0.125; }
  void OnField(const OptionField&, bool& value) override { value = !value; }
  void OnField(const OptionField&, std::string& value) override { value += "_changed"; }
  void OnField(const OptionField&, std::vector<int>& value) override { value.push_back(3); }
  void OnField(const OptionField&, const EnumField&) override {}  // no matcher has one
};

TEST(MatcherRegistry, EveryModelsOptionsRoundTripThroughJson) {
  for (const auto& model : MatcherModels()) {
    SCOPED_TRACE(model.name);
    const auto defaults = model.default_options();
    auto changed = model.default_options();
    ChangeEveryField change;
    changed->VisitFields(change);
    const nlohmann::json json = changed->ToJson();
    EXPECT_EQ(json["type"], model.name);
    const nlohmann::json default_json = defaults->ToJson();
    ASSERT_EQ(json.size(), default_json.size());
    for (const auto& [key, value] : default_json.items()) {
      if (key != "type") {
        EXPECT_NE(json[key], value) << key;
      }
    }
    auto back = model.default_options();
    back->FromJson(json, "options.matcher");
    EXPECT_EQ(back->ToJson(), json);
    // Keys the options do not have (derived values a map records) are ignored; missing keys keep values.
    auto partial = model.default_options();
    partial->FromJson(nlohmann::json{{"type", model.name}, {"coarse_stride", 8}}, "options.matcher");
    EXPECT_EQ(partial->ToJson(), default_json);
  }
}

TEST(MatcherRegistry, AValueOfTheWrongTypeNamesTheField) {
  for (const auto& model : MatcherModels()) {
    auto options = model.default_options();
    const nlohmann::json json = options->ToJson();
    for (const auto& [key, value] : json.items()) {
      if (key == "type") continue;
      nlohmann::json wrong = json;
      wrong[key] = value.is_string() ? nlohmann::json(1) : nlohmann::json("text");
      try {
        options->FromJson(wrong, "options.matcher");
        ADD_FAILURE() << model.name << "." << key << " read from the wrong type";
      } catch (const InputError& error) {
        EXPECT_NE(std::string(error.what()).find("options.matcher." + key), std::string::npos) << error.what();
      }
    }
  }
}

TEST(MatcherRegistry, TypedOptionsAreReachedByTheirStructOnly) {
  MatcherOptions options;
  options.Of<OrbMatcherOptions>().num_features = 1234;
  const MatcherOptions copy = options;  // a deep copy
  options.Of<OrbMatcherOptions>().num_features = 10;
  EXPECT_EQ(copy.Of<OrbMatcherOptions>().num_features, 1234);
  EXPECT_EQ(copy.model("orb").ToJson()["num_features"], 1234);
  EXPECT_THROW(copy.model("loftr").As<OrbMatcherOptions>(), std::logic_error);
  EXPECT_THROW(copy.model("sift"), InputError);
}

bool ProcessMapsName(const std::string& library) {
  std::ifstream maps("/proc/self/maps");
  const std::string text((std::istreambuf_iterator<char>(maps)), std::istreambuf_iterator<char>());
  return text.find(library) != std::string::npos;
}

// Whether an earlier test in this process loaded the plugin, which no test can unload: the two tests below ask
// about a process that has not (ctest runs each test in a process of its own; a whole-binary run may not).
bool PluginLoadedEarlier() { return MatcherPluginLoaded() || ProcessMapsName("libvmap_torch"); }

// ORB never needs LibTorch: creating and using it loads no plugin.
TEST(MatcherRegistry, TheOrbPathDoesNotLoadThePlugin) {
  if (PluginLoadedEarlier()) GTEST_SKIP() << "an earlier test in this process loaded the plugin";
  const auto matcher = CreateMatcher(MatcherOptions{});
  const cv::Mat image(120, 160, CV_8U, cv::Scalar(0));
  matcher->Match(*matcher->Extract(image), *matcher->Extract(image));
  MatcherOptionsFromJson(matcher->DescribeOptionsJson(), "map.json");
  EXPECT_FALSE(MatcherPluginLoaded());
  EXPECT_FALSE(ProcessMapsName("libvmap_torch"));
  EXPECT_FALSE(ProcessMapsName("libtorch"));
}

// A failed load is not remembered: once the plugin is where it is looked for, the next call loads it.
TEST(MatcherRegistry, APluginThatWasMissingLoadsOnALaterCall) {
#if defined(VMAP_WITH_TORCH)
  const std::filesystem::path built = testing::VmapBinary().parent_path() / "libvmap_torch.so";
  const std::filesystem::path beside_tests =
      std::filesystem::read_symlink("/proc/self/exe").parent_path() / "libvmap_torch.so";
  if (!std::filesystem::exists(built)) GTEST_SKIP() << "the plugin is not built";
  if (std::filesystem::exists(beside_tests)) GTEST_SKIP() << beside_tests << " exists already";
  if (PluginLoadedEarlier()) GTEST_SKIP() << "an earlier test in this process loaded the plugin";
  try {
    LoadMatcherPlugin();
    ADD_FAILURE() << "a plugin was found beside the test binary";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(beside_tests.string()), std::string::npos) << error.what();
  }
  EXPECT_FALSE(MatcherPluginLoaded());
  std::filesystem::create_symlink(built, beside_tests);
  const MatcherPluginTable* table = nullptr;
  try {
    table = &LoadMatcherPlugin();
  } catch (const InputError& error) {
    ADD_FAILURE() << error.what();
  }
  std::filesystem::remove(beside_tests);
  ASSERT_NE(table, nullptr);
  EXPECT_TRUE(MatcherPluginLoaded());
  // Its table has a row for every registered model that needs it.
  for (const auto& model : MatcherModels()) {
    if (model.needs_torch) {
      EXPECT_NE(table->Find(model.name), nullptr) << model.name;
    }
  }
#else
  GTEST_SKIP() << "built without LibTorch";
#endif
}

// A plugin cut short (a copy interrupted, a full disk) or of another build is refused naming the file and the fix: the
// loader would map segments beyond the file's end (a bus error), or read a table of another layout.
TEST(MatcherRegistry, APluginCutShortOrOfAnotherBuildIsRefusedNotLoaded) {
#if defined(VMAP_WITH_TORCH)
  const std::filesystem::path built = testing::VmapBinary().parent_path() / "libvmap_torch.so";
  if (!std::filesystem::exists(built)) GTEST_SKIP() << "the plugin is not built";
  const testing::ScopedTempDir tmp("plugin");
  const std::filesystem::path vmap = tmp.path() / "vmap", plugin = tmp.path() / "libvmap_torch.so";
  std::filesystem::copy_file(testing::VmapBinary(), vmap);
  const cv::Mat image(120, 160, CV_8U, cv::Scalar(90));
  cv::imwrite((tmp.path() / "a.png").string(), image);
  const std::vector<std::string> match = {"match", (tmp.path() / "a.png").string(), (tmp.path() / "a.png").string(),
                                          "--matcher", "xfeat"};
  {
    std::ifstream whole(built, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(whole)), std::istreambuf_iterator<char>());
    bytes.resize(bytes.size() / 2);
    std::ofstream(plugin, std::ios::binary) << bytes;
  }
  EXPECT_NE(IncompleteSharedLibraryProblem(plugin.string()).find("it is cut short"), std::string::npos);
  EXPECT_EQ(IncompleteSharedLibraryProblem(built.string()), "");
  auto run = testing::RunBounded(vmap, match, 60);
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_NE(run.output.find(plugin.string() + "', which is "), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("it is cut short; rebuild vmap"), std::string::npos) << run.output;

  std::filesystem::remove(plugin);
  std::filesystem::copy_file(VMAP_FOREIGN_PLUGIN, plugin);
  run = testing::RunBounded(vmap, match, 60);
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_NE(run.output.find("was built for another vmap (vmap 0.0.0, another build) than this one (vmap "),
            std::string::npos)
      << run.output;
#else
  GTEST_SKIP() << "built without LibTorch";
#endif
}

// The same for the binary: `vmap build --matcher orb` and `vmap info` never open LibTorch (the loader's own
// trace of every library it opens).
TEST(MatcherRegistry, TheOrbCommandsDoNotLoadThePlugin) {
  SKIP_WITHOUT_SHARED();
  const testing::ScopedTempDir tmp("registry");
  const std::string map = testing::Quote(tmp.path() / "map");
  const std::string video = testing::Quote(testing::SharedDir() + "/data/lab_floor/lab_floor.mp4");
  const auto build = testing::RunVmap("build " + video + " --last 19 --matcher orb -o " + map, "LD_DEBUG=files");
  const auto info = testing::RunVmap("info " + map, "LD_DEBUG=files");
  ASSERT_EQ(build.status, 0) << build.output;
  ASSERT_EQ(info.status, 0) << info.output;
  for (const std::string& output : {build.output, info.output}) {
    EXPECT_NE(output.find("libopencv_core"), std::string::npos) << "no loader trace:\n" << output;
    EXPECT_EQ(output.find("libvmap_torch"), std::string::npos) << output;
    EXPECT_EQ(output.find("libtorch"), std::string::npos) << output;
  }
}

}  // namespace
}  // namespace vmap
