#include "vmap/cli/option_binder.h"

#include <string>

#include <gtest/gtest.h>

#include "vmap/testing/option_error.h"

namespace vmap::cli {
namespace {

enum class Shape { kRound, kSquare };
constexpr EnumName<Shape> kShapeNames[] = {{Shape::kRound, "round"}, {Shape::kSquare, "square"}};
Shape ParseShape(const std::string& name) { return ParseEnum(kShapeNames, name, "shape"); }

struct Part {
  double threshold = 0.5;
  int budget = 100;
  std::string weights;
  void VisitFields(OptionFieldVisitor& visitor) {
    visitor.Visit(OptionField{"threshold", "--threshold", "Threshold"}.Within(0, 1).ExcludingMin(), threshold);
    visitor.Visit(OptionField{"budget", "--budget", "Budget"}.Within(1, 1000).Or(0), budget);
    visitor.Visit({"weights", "--weights", "Weights file"}, weights);
  }
};

struct Whole {
  Shape shape = Shape::kRound;
  bool final_key = true;
  bool strict = false;
  int threads = 0;
  int unflagged = 3;
  Part part;
  void VisitFields(OptionFieldVisitor& visitor) {
    visitor.Visit(OptionField{"shape", "--shape", "Outline: "}.ListingNames(),
                  EnumField(shape, kShapeNames, ParseShape));
    visitor.Visit({"final_key", "!--no-final-key", "No final key"}, final_key);
    visitor.Visit({"strict", "--strict", "Strict"}, strict);
    visitor.Visit(OptionField{"extraction_threads", "--threads", "Threads"}.NotRecorded(), threads);
    visitor.Visit({"unflagged"}, unflagged);
    visitor.VisitNested("part", part);
  }
};

TEST(OptionBinder, BindsEachFlaggedFieldAndRecordsItsPath) {
  CLI::App app;
  OptionFlags flags;
  Whole whole;
  AddOptionFlags(&app, whole, flags);
  app.parse("--shape square --no-final-key --strict --threads 3 --threshold 0.25 --budget 7", false);
  EXPECT_EQ(whole.shape, Shape::kSquare);
  EXPECT_FALSE(whole.final_key);
  EXPECT_TRUE(whole.strict);
  EXPECT_EQ(whole.threads, 3);
  EXPECT_EQ(whole.part.threshold, 0.25);
  EXPECT_EQ(whole.part.budget, 7);
  EXPECT_EQ(whole.unflagged, 3);
  EXPECT_EQ(flags.FlagOf("shape"), "--shape");
  EXPECT_EQ(flags.FlagOf("final_key"), "--no-final-key");
  EXPECT_EQ(flags.FlagOf("extraction_threads"), "--threads");
  EXPECT_EQ(flags.FlagOf("part.threshold"), "--threshold");
  EXPECT_EQ(flags.FlagOf("unflagged"), "");
  EXPECT_EQ(flags.Message(OptionError("part.budget", "must be 1 to 10")), "--budget must be 1 to 10");
  // The help lists an enum's names and shows each default.
  EXPECT_EQ(app.get_option("--shape")->get_description(), "Outline: round or square");
  EXPECT_EQ(app.get_option("--shape")->get_default_str(), "round");
  EXPECT_EQ(app.get_option("--budget")->get_default_str(), "100");
  // ... and the values a number field takes, after its type.
  EXPECT_EQ(app.get_option("--threshold")->get_type_name(), "FLOAT in (0, 1]");
  EXPECT_EQ(app.get_option("--budget")->get_type_name(), "INT 0 or [1, 1000]");
  EXPECT_EQ(app.get_option("--threads")->get_type_name(), "INT");
}

TEST(OptionBinder, AnUnknownEnumNameIsTheParsersError) {
  CLI::App app;
  OptionFlags flags;
  Whole whole;
  AddOptionFlags(&app, whole, flags);
  EXPECT_EQ(testing::InputErrorMessage([&] { app.parse("--shape oval", false); }),
            "unknown shape 'oval'; use round or square");
}

TEST(OptionBinder, SkipsWhatTheHolderLeavesOutAndSharesAFlagBetweenFields) {
  CLI::App app;
  OptionFlags flags;
  Part first, second;
  OptionBinder binder;
  binder.Add("first", first, Nesting{false, {"budget"}});
  binder.Add("second", second, Nesting{false, {"budget"}});
  binder.Bind(&app, flags);
  EXPECT_EQ(app.get_option_no_throw("--budget"), nullptr);
  app.parse("--weights w.pt --threshold 2", false);
  EXPECT_EQ(first.weights, "w.pt");
  EXPECT_EQ(second.weights, "w.pt");
  EXPECT_EQ(first.threshold, 2.0);
  EXPECT_EQ(second.threshold, 2.0);
  EXPECT_EQ(flags.FlagOf("first.threshold"), "--threshold");
  EXPECT_EQ(flags.FlagOf("second.threshold"), "--threshold");
}

}  // namespace
}  // namespace vmap::cli
