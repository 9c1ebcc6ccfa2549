// An options struct's JSON written and read through its field list (core/option_fields.h).

#include "vmap/core/options_json.h"

#include <gtest/gtest.h>

#include "vmap/testing/option_error.h"

namespace vmap {
namespace {

enum class Shape { kRound, kSquare };
constexpr EnumName<Shape> kShapeNames[] = {{Shape::kRound, "round"}, {Shape::kSquare, "square"}};
Shape ParseShape(const std::string& name) { return ParseEnum(kShapeNames, name, "shape"); }

struct Inner {
  double threshold = 1.0;
  int seed = 0;
  int budget = 10;  // left out by the holder that visits it with a skip
  void VisitFields(OptionFieldVisitor& visitor) {
    visitor.Visit({"threshold"}, threshold);
    visitor.Visit({"seed"}, seed);
    visitor.Visit({"budget"}, budget);
  }
};

struct Outer {
  Shape shape = Shape::kRound;
  bool strict = false;
  std::string camera;  // "" recorded as "input"
  std::string topic;   // recorded only when set
  int threads = 0;     // not recorded
  std::vector<int> route;
  Inner flat;     // its fields at this level
  Inner nested;   // an object "nested"
  Inner trimmed;  // an object "trimmed" without "budget"
  void VisitFields(OptionFieldVisitor& visitor) {
    visitor.Visit(OptionField{"shape"}.Named("outline"), EnumField(shape, kShapeNames, ParseShape));
    visitor.Visit({"strict"}, strict);
    visitor.Visit(OptionField{"camera"}.EmptyAs("input"), camera);
    visitor.Visit(OptionField{"topic"}.OmitEmpty(), topic);
    visitor.Visit(OptionField{"threads"}.NotRecorded(), threads);
    visitor.Visit({"route"}, route);
    visitor.VisitNested("flat", flat, Nesting{true, {}});
    visitor.VisitNested("nested", nested);
    visitor.VisitNested("trimmed", trimmed, Nesting{false, {"budget"}});
  }
};

TEST(OptionsJson, WritesEachRecordedFieldByItsKey) {
  Outer options;
  options.threads = 4;
  options.flat.seed = 3;
  const nlohmann::json expected = {{"shape", "round"},
                                   {"strict", false},
                                   {"camera", "input"},
                                   {"route", nlohmann::json::array()},
                                   {"threshold", 1.0},
                                   {"seed", 3},
                                   {"budget", 10},
                                   {"nested", {{"threshold", 1.0}, {"seed", 0}, {"budget", 10}}},
                                   {"trimmed", {{"threshold", 1.0}, {"seed", 0}}}};
  EXPECT_EQ(OptionsToJson(options), expected);
  options.topic = "/camera/image";
  options.camera = "525,525,320,240";
  const nlohmann::json written = OptionsToJson(options);
  EXPECT_EQ(written["topic"], "/camera/image");
  EXPECT_EQ(written["camera"], "525,525,320,240");
}

TEST(OptionsJson, ReadsBackWhatItWroteAndKeepsWhatARecordLacks) {
  Outer written;
  written.shape = Shape::kSquare;
  written.strict = true;
  written.topic = "/t";
  written.route = {2, 5, 7};
  written.flat.threshold = 0.25;
  written.nested.seed = 9;
  written.trimmed.budget = 99;  // not recorded by its holder
  Outer read;
  read.threads = 6;
  OptionsFromJson(JsonFieldReader(OptionsToJson(written), "options"), &read);
  EXPECT_EQ(read.shape, Shape::kSquare);
  EXPECT_TRUE(read.strict);
  EXPECT_EQ(read.camera, "");  // "input" is the empty default
  EXPECT_EQ(read.topic, "/t");
  EXPECT_EQ(read.threads, 6);
  EXPECT_EQ(read.route, (std::vector<int>{2, 5, 7}));
  EXPECT_EQ(read.flat.threshold, 0.25);
  EXPECT_EQ(read.nested.seed, 9);
  EXPECT_EQ(read.trimmed.budget, 10);
  EXPECT_EQ(OptionsToJson(read), OptionsToJson(written));

  Outer partly;
  OptionsFromJson(JsonFieldReader(nlohmann::json{{"nested", {{"seed", 4}}}, {"unknown", 1}}, "options"), &partly);
  EXPECT_EQ(partly.nested.seed, 4);
  EXPECT_EQ(partly.nested.threshold, 1.0);
  EXPECT_EQ(partly.shape, Shape::kRound);
}

TEST(OptionsJson, AWrongValueNamesItsKeyByItsPath) {
  Outer options;
  auto error = [&](const nlohmann::json& record) {
    return testing::InputErrorMessage([&] { OptionsFromJson(JsonFieldReader(record, "map 'm': options"), &options); });
  };
  EXPECT_EQ(error({{"nested", {{"seed", 1.5}}}}), "map 'm': options.nested.seed must be an integer (it is number)");
  EXPECT_EQ(error({{"shape", "oval"}}),
            "map 'm': options.shape is 'oval', which this vmap does not know (it knows round or square)");
  EXPECT_EQ(error({{"route", {1, "2"}}}), "map 'm': options.route must be an array of integers (it holds \"2\")");
  EXPECT_EQ(error({{"trimmed", 3}}), "map 'm': options.trimmed must be a JSON object (it is number)");
}

// Paths as OptionError names them: the nested struct's name, even where its JSON is inline; a field's name
// where it differs from its key.
class PathRecorder final : public OptionFieldVisitor {
 public:
  std::vector<std::string> paths;

 protected:
  void OnField(const OptionField& field, int&) override { paths.push_back(Path(field)); }
  void OnField(const OptionField& field, double&) override { paths.push_back(Path(field)); }
  void OnField(const OptionField& field, bool&) override { paths.push_back(Path(field)); }
  void OnField(const OptionField& field, std::string&) override { paths.push_back(Path(field)); }
  void OnField(const OptionField& field, std::vector<int>&) override { paths.push_back(Path(field)); }
  void OnField(const OptionField& field, const EnumField&) override { paths.push_back(Path(field)); }
};

TEST(OptionFields, PathsNameTheFieldWithinTheStructVisited) {
  Outer options;
  PathRecorder recorder;
  recorder.VisitNested("outer", options);
  EXPECT_EQ(recorder.paths,
            (std::vector<std::string>{"outer.outline", "outer.strict", "outer.camera", "outer.topic", "outer.threads",
                                      "outer.route", "outer.flat.threshold", "outer.flat.seed", "outer.flat.budget",
                                      "outer.nested.threshold", "outer.nested.seed", "outer.nested.budget",
                                      "outer.trimmed.threshold", "outer.trimmed.seed"}));
}

// An optional number is written as null while unset, and read back either way.
struct WithOptional {
  std::optional<double> tau;
  void VisitFields(OptionFieldVisitor& visitor) { visitor.Visit({"tau"}, tau); }
};

TEST(OptionsJson, AnUnsetOptionalNumberIsNull) {
  WithOptional options;
  EXPECT_EQ(OptionsToJson(options).dump(), R"({"tau":null})");
  options.tau = 0.25;
  EXPECT_EQ(OptionsToJson(options).dump(), R"({"tau":0.25})");
  WithOptional back;
  OptionsFromJson(JsonFieldReader(OptionsToJson(options), "x"), &back);
  EXPECT_EQ(back.tau, 0.25);
  OptionsFromJson(JsonFieldReader(nlohmann::json::parse(R"({"tau":null})"), "x"), &back);
  EXPECT_FALSE(back.tau.has_value());
  back.tau = 0.5;
  OptionsFromJson(JsonFieldReader(nlohmann::json::object(), "x"), &back);  // missing: kept
  EXPECT_EQ(back.tau, 0.5);
  const std::string wrong = testing::InputErrorMessage(
      [&] { OptionsFromJson(JsonFieldReader(nlohmann::json::parse(R"({"tau":"x"})"), "r"), &back); });
  EXPECT_EQ(wrong.rfind("r.tau ", 0), 0u) << wrong;
}

}  // namespace
}  // namespace vmap
