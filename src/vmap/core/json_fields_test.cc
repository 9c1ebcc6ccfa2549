#include "vmap/core/json_fields.h"

#include <gtest/gtest.h>

#include "vmap/testing/option_error.h"

namespace vmap {
namespace {

enum class Fruit { kApple, kPear };
constexpr EnumName<Fruit> kFruitNames[] = {{Fruit::kApple, "apple"}, {Fruit::kPear, "pear"}};
Fruit ParseFruit(const std::string& name) { return ParseEnum(kFruitNames, name, "fruit"); }

TEST(JsonFieldReader, ReadsRecordedFieldsAndKeepsTheOthers) {
  const nlohmann::json record = {{"tau", 0.7},      {"seed", 3},       {"strict", true}, {"resize", "640"},
                                 {"fruit", "pear"}, {"note", nullptr}, {"newer", 1}};
  const JsonFieldReader fields(record, "options");
  double tau = 0.5, missing = 2.5;
  int seed = 0;
  bool strict = false;
  std::string resize, note = "kept";
  Fruit fruit = Fruit::kApple;
  fields.Read("tau", &tau);
  fields.Read("seed", &seed);
  fields.Read("strict", &strict);
  fields.Read("resize", &resize);
  fields.Read("fruit", EnumField(fruit, kFruitNames, ParseFruit));
  fields.Read("note", &note);       // null: as if not recorded
  fields.Read("absent", &missing);  // an older record
  EXPECT_EQ(tau, 0.7);
  EXPECT_EQ(seed, 3);
  EXPECT_TRUE(strict);
  EXPECT_EQ(resize, "640");
  EXPECT_EQ(fruit, Fruit::kPear);
  EXPECT_EQ(note, "kept");
  EXPECT_EQ(missing, 2.5);
  double integer_as_double = 0;
  fields.Read("seed", &integer_as_double);  // a whole number is a number
  EXPECT_EQ(integer_as_double, 3.0);
}

TEST(JsonFieldReader, AValueOfTheWrongKindNamesItsPath) {
  const nlohmann::json record = {{"tau", "high"}, {"seed", 1.5},    {"strict", 1},
                                 {"big", 1e12},   {"fruit", "fig"}, {"pose", {{"threshold", true}}},
                                 {"list", {1, 2}}};
  const JsonFieldReader fields(record, "map 'm/map.json': options");
  double tau = 0;
  int seed = 0, big = 0;
  bool strict = false;
  Fruit fruit = Fruit::kApple;
  EXPECT_EQ(testing::InputErrorMessage([&] { fields.Read("tau", &tau); }),
            "map 'm/map.json': options.tau must be a number (it is string)");
  EXPECT_EQ(testing::InputErrorMessage([&] { fields.Read("seed", &seed); }),
            "map 'm/map.json': options.seed must be an integer (it is number)");
  EXPECT_EQ(testing::InputErrorMessage([&] { fields.Read("strict", &strict); }),
            "map 'm/map.json': options.strict must be true or false (it is number)");
  EXPECT_NE(testing::InputErrorMessage([&] { fields.Read("big", &big); }).find("options.big must be an integer"),
            std::string::npos);
  EXPECT_EQ(testing::InputErrorMessage([&] { fields.Read("fruit", EnumField(fruit, kFruitNames, ParseFruit)); }),
            "map 'm/map.json': options.fruit is 'fig', which this vmap does not know (it knows apple or pear)");
  double threshold = 0;
  EXPECT_EQ(testing::InputErrorMessage([&] { fields.Object("pose").Read("threshold", &threshold); }),
            "map 'm/map.json': options.pose.threshold must be a number (it is boolean)");
  EXPECT_EQ(testing::InputErrorMessage([&] { fields.Object("list"); }),
            "map 'm/map.json': options.list must be a JSON object (it is array)");
  EXPECT_EQ(testing::InputErrorMessage([] { JsonFieldReader(nlohmann::json::array(), "options"); }),
            "options is not a JSON object (it is array)");
  EXPECT_EQ(tau, 0.0);  // nothing was read from a bad value
  EXPECT_EQ(fruit, Fruit::kApple);
}

TEST(JsonFieldReader, AMissingObjectReadsAsEmpty) {
  const JsonFieldReader fields(nlohmann::json::object(), "options");
  double threshold = 0.5;
  fields.Object("pose").Read("threshold", &threshold);
  EXPECT_EQ(threshold, 0.5);
  EXPECT_EQ(fields.Object("pose").Path("threshold"), "options.pose.threshold");
}

}  // namespace
}  // namespace vmap
