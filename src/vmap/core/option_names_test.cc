#include "vmap/core/option_names.h"

#include <map>

#include <gtest/gtest.h>

namespace vmap {
namespace {

std::string Named(const OptionError& error) {
  const std::map<std::string, std::string> names = {{"csv", "--csv"}, {"json", "--json"}, {"first", "--first"}};
  return OptionErrorMessage(error, [&](const std::string& path) {
    const auto it = names.find(path);
    return it == names.end() ? std::string() : it->second;
  });
}

TEST(OptionNames, NamesTheFieldAndTheOthersItMentions) {
  EXPECT_EQ(Named(OptionError("csv", "'a' is also the output of json; give each output its own file", {"json"})),
            "--csv 'a' is also the output of --json; give each output its own file");
  EXPECT_EQ(Named(OptionError("last", "3 is before first 5", {"first"})), "last 3 is before --first 5");
}

// A name inside a quoted value (a path) is the value's, not the field's; an apostrophe opens no quote.
TEST(OptionNames, LeavesQuotedValuesAlone) {
  EXPECT_EQ(Named(OptionError("csv", "'/tmp/json/x' is also the output of json", {"json"})),
            "--csv '/tmp/json/x' is also the output of --json");
  EXPECT_EQ(Named(OptionError("csv", "'x' would overwrite the map's json file 'm/json'", {"json"})),
            "--csv 'x' would overwrite the map's --json file 'm/json'");
}

}  // namespace
}  // namespace vmap
