#include "vmap/cli/option_flags.h"

#include <stdexcept>
#include <string>
#include <system_error>

#include <gtest/gtest.h>

#include "vmap/cli/option_binder.h"
#include "vmap/features/matcher_registry.h"
#include "vmap/features/orb_matcher.h"
#include "vmap/pipelines/simulate_pipeline.h"

namespace vmap::cli {
namespace {

TEST(OptionFlags, RecordsTheLongNameOfEachBoundFlag) {
  CLI::App app;
  OptionFlags flags;
  double tau = 0.5;
  bool final_key = true;
  int threads = 0;
  flags.AddOption(&app, "-t,--tau", tau, "key_images.tau", "");
  flags.AddFlag(&app, "!--no-final-key", final_key, "key_images.final_key", "");
  flags.AddOption(&app, "--threads", threads, "extraction_threads", "");
  EXPECT_EQ(flags.FlagOf("key_images.tau"), "--tau");
  EXPECT_EQ(flags.FlagOf("key_images.final_key"), "--no-final-key");
  EXPECT_EQ(flags.FlagOf("extraction_threads"), "--threads");
  EXPECT_EQ(flags.FlagOf("prefetch_frames"), "");
  // The bound field is still what the flag sets.
  app.parse("--threads 7", false);
  EXPECT_EQ(threads, 7);
}

TEST(OptionFlags, SaysAnErrorWithTheFlagsOfItsFields) {
  OptionFlags flags;
  flags.Record("extraction_threads", "--threads");
  flags.Record("exhaustive", "--exhaustive");
  flags.Record("key_search", "--search");
  EXPECT_EQ(flags.Message(OptionError("extraction_threads", "must be 0 to 256 (0 = one per core)")),
            "--threads must be 0 to 256 (0 = one per core)");
  EXPECT_EQ(flags.Message(
                OptionError("exhaustive", "is a scan and key_search bisect skips frames; drop one", {"key_search"})),
            "--exhaustive is a scan and --search bisect skips frames; drop one");
  // A field without a flag keeps its path; so does a named field without one.
  EXPECT_EQ(flags.Message(OptionError("prefetch_frames", "must be 1 to 1024", {"search_window"})),
            "prefetch_frames must be 1 to 1024");
  EXPECT_EQ(flags.Message(OptionError("exhaustive", "conflicts with search_window", {"search_window"})),
            "--exhaustive conflicts with search_window");
}

TEST(OptionFlags, ReplacesOnlyWholeNames) {
  OptionFlags flags;
  flags.Record("last", "--last");
  flags.Record("first", "--first");
  EXPECT_EQ(flags.Message(OptionError("last", "3 is the first_frame before first 5", {"first"})),
            "--last 3 is the first_frame before --first 5");
  EXPECT_EQ(flags.Message(OptionError("last", "3 is before first.", {"first"})), "--last 3 is before --first.");
}

TEST(OptionFlags, TranslatesNestedPaths) {
  OptionFlags flags;
  flags.Record("link_analysis.pose.threshold", "--pose-threshold");
  const OptionError nested =
      OptionError("threshold", "-1 px is outside (0, 100]").Within("pose").Within("link_analysis");
  EXPECT_EQ(flags.Message(nested), "--pose-threshold -1 px is outside (0, 100]");
}

TEST(OptionFlags, AFieldWithTwoFlagsIsAProgrammingError) {
  OptionFlags flags;
  flags.Record("extraction_threads", "--threads");
  flags.Record("extraction_threads", "--threads");  // the same binding twice is harmless
  EXPECT_THROW(flags.Record("extraction_threads", "--jobs"), std::logic_error);
}

TEST(OptionFlags, RunTurnsOptionErrorsIntoInputErrorsInTheFlagsWords) {
  OptionFlags flags;
  flags.Record("verifier.seed", "--seed");
  try {
    flags.Run([] { throw OptionError("seed", "must be >= 0 (default 0)").Within("verifier"); });
    FAIL() << "expected InputError";
  } catch (const OptionError&) {
    FAIL() << "the OptionError came through untranslated";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(), "--seed must be >= 0 (default 0)");
  }
  // Other errors pass unchanged.
  EXPECT_THROW(flags.Run([] { throw std::runtime_error("x"); }), std::runtime_error);
  bool ran = false;
  flags.Run([&] { ran = true; });
  EXPECT_TRUE(ran);
}

// Every matcher model's flag is recorded under the path MatcherOptions::Check() names.
TEST(OptionFlags, MatcherFlagsAreRecordedByModelAndKey) {
  CLI::App app;
  MatcherOptions options;
  OptionFlags flags;
  AddOptionFlags(&app, options, flags);
  EXPECT_EQ(flags.FlagOf("orb.num_features"), "--orb-features");
  EXPECT_EQ(flags.FlagOf("orb.ratio"), "--ratio");
  options.Of<OrbMatcherOptions>().num_features = 0;
  try {
    flags.Run([&] { options.Check(); });
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()).rfind("--orb-features 0 is outside [1, 100000]", 0), 0u) << error.what();
  }
}

// `vmap simulate` takes `vmap localize`'s flags for its localizer (the options struct's fields, visited once), so a
// rule can be turned off in the closed loop as in a localization run; the struct reaches every trial
// (ClosedLoop.TheLocalizersOptionsReachEveryTrialsLocalizer).
TEST(OptionFlags, TheSimulatorTakesTheLocalizersFlags) {
  SimulatePipelineOptions pipeline;
  CLI::App app;
  OptionFlags flags;
  AddOptionFlags(&app, pipeline, flags);
  app.parse("--no-rank-by-standout --scene-change-log10-nfa -40 --scene-change-tracked-log10-nfa -500 --candidates 7",
            false);
  const LocalizerOptions& localizer = pipeline.simulation.localizer;
  EXPECT_FALSE(localizer.rank_by_standout);
  EXPECT_EQ(localizer.scene_change_log10_nfa, -40.0);
  EXPECT_EQ(localizer.scene_change_tracked_log10_nfa, -500.0);
  EXPECT_EQ(localizer.relocalization_candidates, 7);
}

// A thread that cannot start (this user's process limit reached) is said as such, with what to do; any other
// error keeps its own text.
TEST(OptionFlags, AThreadThatCannotStartIsNamedWithTheLimit) {
  const std::system_error no_thread(std::make_error_code(std::errc::resource_unavailable_try_again));
  const std::string message = ThreadErrorMessage(no_thread);
  EXPECT_EQ(message.rfind("cannot start a thread (Resource temporarily unavailable)", 0), 0u) << message;
  EXPECT_NE(message.find("(ulimit -u); use fewer --threads"), std::string::npos) << message;
  EXPECT_EQ(ThreadErrorMessage(std::runtime_error("other")), "other");
  EXPECT_EQ(ThreadErrorMessage(std::system_error(std::make_error_code(std::errc::permission_denied), "x")),
            std::system_error(std::make_error_code(std::errc::permission_denied), "x").what());
}

}  // namespace
}  // namespace vmap::cli
