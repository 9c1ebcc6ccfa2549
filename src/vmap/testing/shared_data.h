#pragma once
// The shared data folder (../shared: real sequences, weights, golden outputs), which tests use where it is
// present and skip without.

#include <string>

#include <gtest/gtest.h>

namespace vmap::testing {

// The shared folder (CMake's VMAP_SHARED_DIR, ../shared by default) when it holds data/, or empty when it is
// absent. A string, so that a test may write SharedDir() + "/golden/x" as well as fs::path(SharedDir()) / "x".
std::string SharedDir();
bool SharedDataPresent();
// Why a test skips without it: names the folder that was looked for.
std::string NoSharedDataMessage();

}  // namespace vmap::testing

// First in a test that needs the shared data.
#define SKIP_WITHOUT_SHARED() \
  if (!::vmap::testing::SharedDataPresent()) GTEST_SKIP() << ::vmap::testing::NoSharedDataMessage()
