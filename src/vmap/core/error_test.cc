#include "vmap/core/error.h"

#include <string>

#include <gtest/gtest.h>

namespace vmap {
namespace {

struct Leaf {
  double threshold = 1.0;
  void Check() const {
    if (!(threshold > 0.0)) throw OptionError("threshold", "must be > 0", {"other"});
  }
};

struct Middle {
  Leaf pose;
  void Check() const { CheckField("pose", pose); }
};

struct Root {
  Middle link_analysis;
  void Check() const { CheckField("link_analysis", link_analysis); }
};

TEST(OptionError, NamesTheFieldAndTheProblem) {
  const OptionError error("extraction_threads", "must be 0 to 256 (0 = one per core)");
  EXPECT_STREQ(error.what(), "extraction_threads must be 0 to 256 (0 = one per core)");
  EXPECT_EQ(error.path(), "extraction_threads");
  EXPECT_EQ(error.problem(), "must be 0 to 256 (0 = one per core)");
  EXPECT_TRUE(error.others().empty());
  // Every catch of InputError still catches it (the CLI's exit status 2).
  EXPECT_THROW(throw error, InputError);
}

TEST(OptionError, OtherFieldsAreSiblingsOfThePath) {
  const OptionError error("key_images.tau", "is too low for similarity", {"similarity"});
  ASSERT_EQ(error.others().size(), 1u);
  EXPECT_EQ(error.others()[0], "key_images.similarity");
}

TEST(OptionError, WithinPrefixesThePathAndTheOtherFields) {
  const OptionError nested = OptionError("tau", "0 is outside (0, 1]", {"similarity"}).Within("key_images");
  EXPECT_EQ(nested.path(), "key_images.tau");
  EXPECT_EQ(nested.problem(), "0 is outside (0, 1]");
  EXPECT_STREQ(nested.what(), "key_images.tau 0 is outside (0, 1]");
  ASSERT_EQ(nested.others().size(), 1u);
  EXPECT_EQ(nested.others()[0], "key_images.similarity");
}

TEST(OptionError, NestedChecksNameTheWholePath) {
  Root root;
  root.Check();  // the defaults pass
  root.link_analysis.pose.threshold = -1.0;
  try {
    root.Check();
    FAIL() << "expected OptionError";
  } catch (const OptionError& error) {
    EXPECT_EQ(error.path(), "link_analysis.pose.threshold");
    EXPECT_STREQ(error.what(), "link_analysis.pose.threshold must be > 0");
    ASSERT_EQ(error.others().size(), 1u);
    EXPECT_EQ(error.others()[0], "link_analysis.pose.other");
  }
}

TEST(OptionError, OnlyOptionErrorsAreRenamed) {
  try {
    NameOptionErrorsWithin("verifier", [] { throw InputError("cannot read 'a.png'"); });
    FAIL() << "expected InputError";
  } catch (const OptionError&) {
    FAIL() << "an InputError became an OptionError";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(), "cannot read 'a.png'");
  }
  EXPECT_EQ(NameOptionErrorsWithin("verifier", [] { return 7; }), 7);
}

}  // namespace
}  // namespace vmap
