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

// The parser's error, named by the flag as a number flag's error is (it named no flag: "unknown control law ...").
TEST(OptionBinder, AnUnknownEnumNameIsTheParsersErrorNamedByTheFlag) {
  CLI::App app;
  OptionFlags flags;
  Whole whole;
  AddOptionFlags(&app, whole, flags);
  EXPECT_EQ(testing::InputErrorMessage([&] { app.parse("--shape oval", false); }),
            "--shape: unknown shape 'oval'; use round or square");
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

// A struct's sections are --help's headings: a nested struct's ends with it, and one the holder begins goes on into
// a nested struct that begins none.
struct Sectioned {
  int budget = 1;
  int seed = 0;
  int threads = 0;
  Part part;
  Whole whole;
  void VisitFields(OptionFieldVisitor& visitor) {
    visitor.Visit({"budget", "--budget", "Budget"}, budget);  // no section: the command's "Options"
    visitor.Section("Parts");
    visitor.VisitNested("part", part, Nesting{false, {"budget"}});
    visitor.VisitNested("whole", whole, Nesting{false, {"extraction_threads", "part"}});
    visitor.Visit({"seed", "--seed", "Seed"}, seed);
    visitor.Section(kRunSection);
    visitor.Visit({"threads", "--threads", "Threads"}, threads);
  }
};

struct SectionedInside {
  int first = 0;
  Sectioned sectioned;
  int last = 0;
  void VisitFields(OptionFieldVisitor& visitor) {
    visitor.Section("Outside");
    visitor.Visit({"first", "--first", "First"}, first);
    visitor.VisitNested("", sectioned);
    visitor.Visit({"last", "--last", "Last"}, last);
  }
};

TEST(OptionBinder, ListsEachFlagUnderItsSectionInHelp) {
  CLI::App app;
  OptionFlags flags;
  SectionedInside options;
  AddOptionFlags(&app, options, flags);
  EXPECT_EQ(app.get_option("--first")->get_group(), "Outside");
  EXPECT_EQ(app.get_option("--budget")->get_group(), "Outside");  // the holder's, where the nested struct has none yet
  EXPECT_EQ(app.get_option("--threshold")->get_group(), "Parts");
  EXPECT_EQ(app.get_option("--shape")->get_group(), "Parts");
  EXPECT_EQ(app.get_option("--seed")->get_group(), "Parts");
  EXPECT_EQ(app.get_option("--threads")->get_group(), kRunSection);
  EXPECT_EQ(app.get_option("--last")->get_group(), "Outside");  // the nested struct's sections ended with it
  // --help lists the headings in the order each first appears.
  const std::string help = app.help();
  const size_t outside = help.find("Outside:"), parts = help.find("Parts:"), run = help.find(kRunSection);
  ASSERT_NE(outside, std::string::npos);
  ASSERT_NE(parts, std::string::npos);
  ASSERT_NE(run, std::string::npos);
  EXPECT_LT(outside, parts);
  EXPECT_LT(parts, run);
  EXPECT_LT(help.find("--threshold"), run);
  EXPECT_GT(help.find("--threads"), run);

  CLI::App plain;
  OptionFlags plain_flags;
  Sectioned sectioned;
  AddOptionFlags(&plain, sectioned, plain_flags);
  EXPECT_EQ(plain.get_option("--budget")->get_group(), "Options");
}

}  // namespace
}  // namespace vmap::cli
