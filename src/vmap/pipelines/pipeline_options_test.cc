// Every pipeline's options struct describes each field once: one path per field, a flag per option, defaults
// that pass its check.

#include <map>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "vmap/core/error.h"
#include "vmap/pipelines/add_experience_pipeline.h"
#include "vmap/pipelines/build_pipeline.h"
#include "vmap/pipelines/draw_pipeline.h"
#include "vmap/pipelines/eval_pipeline.h"
#include "vmap/pipelines/localize_pipeline.h"
#include "vmap/pipelines/match_pipeline.h"
#include "vmap/pipelines/report_pipeline.h"
#include "vmap/pipelines/route_pipeline.h"
#include "vmap/pipelines/simulate_pipeline.h"
#include "vmap/pipelines/sweep_pipeline.h"

namespace vmap {
namespace {

// Every field's path and flag, in the order visited.
class FieldLister final : public OptionFieldVisitor {
 public:
  std::vector<std::pair<std::string, std::string>> fields;  // path, flag
  std::set<std::string> positional;

 protected:
  void OnField(const OptionField& f, int&) override { Add(f); }
  void OnField(const OptionField& f, double&) override { Add(f); }
  void OnField(const OptionField& f, bool&) override { Add(f); }
  void OnField(const OptionField& f, std::string&) override { Add(f); }
  void OnField(const OptionField& f, std::vector<int>&) override { Add(f); }
  void OnField(const OptionField& f, const EnumField&) override { Add(f); }
  void OnField(const OptionField& f, std::optional<double>&) override { Add(f); }

 private:
  void Add(const OptionField& field) {
    fields.emplace_back(Path(field), field.flag);
    if (field.positional) positional.insert(Path(field));
  }
};

template <typename Options>
void ExpectDescribedOnce(Options options, const std::set<std::string>& expected_positional) {
  FieldLister lister;
  options.VisitFields(lister);
  std::map<std::string, std::string> flag_of;
  for (const auto& [path, flag] : lister.fields) {
    EXPECT_TRUE(flag_of.emplace(path, flag).second) << "field " << path << " visited twice";
  }
  EXPECT_EQ(lister.positional, expected_positional);
  // A flag names one field, but where several matcher models share it (--weights, --device).
  std::map<std::string, std::vector<std::string>> fields_of;
  for (const auto& [path, flag] : lister.fields) {
    if (!flag.empty()) fields_of[flag].push_back(path);
  }
  for (const auto& [flag, paths] : fields_of) {
    if (flag == "--weights" || flag == "--device") continue;
    EXPECT_EQ(paths.size(), 1u) << flag << " names " << paths.size() << " fields";
  }
  options.Check();  // the defaults pass
}

TEST(PipelineOptions, EachFieldIsDescribedOnceAndTheDefaultsPass) {
  ExpectDescribedOnce(BuildPipelineOptions(), {"input"});
  ExpectDescribedOnce(AddExperiencePipelineOptions(), {"input"});
  ExpectDescribedOnce(LocalizePipelineOptions(), {"map", "query"});
  ExpectDescribedOnce(SweepPipelineOptions(), {"input"});
  ExpectDescribedOnce(RoutePipelineOptions(), {"map"});
  ExpectDescribedOnce(EvalPipelineOptions(), {"map"});
  ExpectDescribedOnce(ReportPipelineOptions(), {"target"});
  ExpectDescribedOnce(PairMatchOptions(), {});
  ExpectDescribedOnce(MatchPipelineOptions(), {"image0", "image1"});
  ExpectDescribedOnce(DrawPipelineOptions(), {"map"});
  ExpectDescribedOnce(SimulatePipelineOptions(), {});
}

// A negative link is refused by the options, naming the field (the CLI's --link, before any map is read).
TEST(PipelineOptions, DrawRefusesANegativeLink) {
  DrawPipelineOptions draw;
  draw.link = -1;
  try {
    draw.Check();
    FAIL() << "a negative link passed";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.path(), "link");
  }
}

// The paths the fields are visited under are the ones their checks name, so that a front end can name a bad
// option by its flag or keyword.
TEST(PipelineOptions, ChecksNameVisitedPaths) {
  FieldLister lister;
  BuildPipelineOptions build;
  build.VisitFields(lister);
  std::set<std::string> paths;
  for (const auto& field : lister.fields) paths.insert(field.first);
  for (const char* path :
       {"tau", "first", "stride", "verifier.threshold", "key_images.similarity", "link_analysis.pose.threshold",
        "orb.num_features", "matcher", "snapshot_every", "key_search", "extraction_threads"}) {
    EXPECT_EQ(paths.count(path), 1u) << path;
  }
}

}  // namespace
}  // namespace vmap
