// A struct's Check() of its number fields' ranges, as its field list gives them (core/option_ranges.h).

#include "vmap/core/option_ranges.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "vmap/core/error.h"
#include "vmap/testing/option_error.h"

namespace vmap {
namespace {

struct Part {
  int budget = 10;
  void VisitFields(OptionFieldVisitor& visitor) { visitor.Visit(OptionField{"budget"}.Within(1, 100), budget); }
  void Check() const { CheckFieldRanges(*this); }
};

struct Whole {
  int threads = 2;
  double share = 0.5;
  double ratio = 2.0;
  int seed = -1;
  double width = 0.1;
  double mass = 0.8;
  std::optional<double> tau;
  double gap = 1.0;
  int unchecked = 7;
  Part part;
  void VisitFields(OptionFieldVisitor& visitor) {
    visitor.Visit(OptionField{"threads", "--threads"}.Within(1, 64), threads);
    visitor.Visit(OptionField{"share"}.Within(0, 1).Meaning("0: never"), share);
    visitor.Visit(OptionField{"ratio"}.Within(1, 1000).Or(0).Meaning("0: never"), ratio);
    visitor.Visit(OptionField{"seed"}.AtLeast(-1).Meaning("-1: the map's"), seed);
    visitor.Visit(OptionField{"width"}.Within(0, 1).ExcludingMin(), width);
    visitor.Visit(OptionField{"mass"}.Within(0, 1).ExcludingMax(), mass);
    visitor.Visit(OptionField{"tau"}.Within(0, 1).ExcludingMin(), tau);
    visitor.Visit(OptionField{"gap"}.AtLeast(0).Unit("px"), gap);
    visitor.Visit({"unchecked"}, unchecked);
    visitor.VisitNested("part", part);
  }
  void Check() const {
    CheckFieldRanges(*this);
    CheckField("part", part);
  }
};

std::string Message(const Whole& options) {
  return testing::InputErrorMessage([&] { options.Check(); });
}

TEST(OptionRanges, TakesEveryValueInsideTheRangesAndTheirEnds) {
  Whole options;
  EXPECT_EQ(Message(options), "");
  options.threads = 1;
  options.share = 0.0;
  options.ratio = 0.0;  // the value outside [1, 1000] that means "never"
  options.seed = -1;
  options.width = 1.0;
  options.mass = 0.0;
  options.tau = 1.0;
  options.gap = 0.0;
  options.unchecked = -1000000;
  EXPECT_EQ(Message(options), "");
  options.threads = 64;
  options.share = 1.0;
  options.ratio = 1000.0;
  options.seed = 1000000000;
  EXPECT_EQ(Message(options), "");
}

TEST(OptionRanges, NamesTheFieldTheValueTheRangeTheDefaultAndWhatAValueMeans) {
  const auto message = [](auto change) {
    Whole options;
    change(options);
    return Message(options);
  };
  EXPECT_EQ(message([](Whole& o) { o.threads = 65; }), "threads 65 is outside [1, 64] (default 2)");
  EXPECT_EQ(message([](Whole& o) { o.threads = 0; }), "threads 0 is outside [1, 64] (default 2)");
  EXPECT_EQ(message([](Whole& o) { o.share = -0.25; }), "share -0.25 is outside [0, 1] (default 0.5; 0: never)");
  EXPECT_EQ(message([](Whole& o) { o.ratio = 0.5; }), "ratio 0.5 is not 0 nor in [1, 1000] (default 2; 0: never)");
  EXPECT_EQ(message([](Whole& o) { o.seed = -2; }), "seed -2 is less than -1 (default -1; -1: the map's)");
  EXPECT_EQ(message([](Whole& o) { o.width = 0.0; }), "width 0 is outside (0, 1] (default 0.1)");
  EXPECT_EQ(message([](Whole& o) { o.mass = 1.0; }), "mass 1 is outside [0, 1) (default 0.8)");
  EXPECT_EQ(message([](Whole& o) { o.tau = 0.0; }), "tau 0 is outside (0, 1] (default unset)");
  EXPECT_EQ(message([](Whole& o) { o.gap = -1.5; }), "gap -1.5 px is less than 0 (default 1 px)");
  EXPECT_EQ(message([](Whole& o) { o.gap = std::numeric_limits<double>::infinity(); }),
            "gap inf px is not finite (default 1 px)");
}

TEST(OptionRanges, RefusesNotANumberAndInfinity) {
  Whole options;
  options.share = std::nan("");
  EXPECT_EQ(testing::OptionErrorPath([&] { options.Check(); }), "share");
  options.share = 0.5;
  options.width = std::numeric_limits<double>::infinity();
  EXPECT_EQ(testing::OptionErrorPath([&] { options.Check(); }), "width");
}

TEST(OptionRanges, LeavesANestedStructToItsOwnCheckWhichNamesItWithin) {
  Whole options;
  options.part.budget = 0;
  // The holder's ranges alone pass: the part's field is the part's to check.
  EXPECT_NO_THROW(CheckFieldRanges(options));
  EXPECT_EQ(Message(options), "part.budget 0 is outside [1, 100] (default 10)");
}

TEST(OptionRanges, RangeTextIsWhatAHelpShows) {
  const auto text = [](const OptionField& field, bool integral) { return RangeText(field.range, integral); };
  EXPECT_EQ(text(OptionField{"a"}.Within(1, 100000), true), "[1, 100000]");
  EXPECT_EQ(text(OptionField{"a"}.Within(0, 1).ExcludingMin(), false), "(0, 1]");
  EXPECT_EQ(text(OptionField{"a"}.Within(0, 1).ExcludingMax(), false), "[0, 1)");
  EXPECT_EQ(text(OptionField{"a"}.AtLeast(-1), true), "[-1, 2147483647]");  // an int's own end
  EXPECT_EQ(text(OptionField{"a"}.AtLeast(-1), false), "[-1, inf)");
  EXPECT_EQ(text(OptionField{"a"}.Within(1, 1000).Or(0), false), "0 or [1, 1000]");
  EXPECT_EQ(text(OptionField{"a"}.Within(0.05, 100), false), "[0.05, 100]");
}

}  // namespace
}  // namespace vmap
