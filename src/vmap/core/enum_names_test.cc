#include "vmap/core/enum_names.h"

#include <gtest/gtest.h>

namespace vmap {
namespace {

enum class Fruit { kApple, kPear, kPlum, kFig };
constexpr EnumName<Fruit> kFruitNames[] = {{Fruit::kApple, "apple"}, {Fruit::kPear, "pear"}, {Fruit::kPlum, "plum"}};
constexpr EnumName<Fruit> kOneFruit[] = {{Fruit::kFig, "fig"}};

TEST(EnumNames, ParsesAndNamesEveryEntryBothWays) {
  for (const auto& entry : kFruitNames) {
    EXPECT_EQ(ParseEnum(kFruitNames, entry.name, "fruit"), entry.value);
    EXPECT_STREQ(EnumToName(kFruitNames, entry.value), entry.name);
  }
}

TEST(EnumNames, UnknownNamesListTheKnownOnes) {
  try {
    ParseEnum(kFruitNames, "Apple", "fruit");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "unknown fruit 'Apple'; use apple, pear or plum");
  }
  EXPECT_EQ(ListEnumNames(kOneFruit), "fig");
  EXPECT_THROW(EnumToName(kFruitNames, Fruit::kFig), std::logic_error);
}

}  // namespace
}  // namespace vmap
