// main() of every vmap test binary: the process set up as the vmap binary has it (core/runtime.h), then
// GoogleTest.

#include <gtest/gtest.h>

#include "vmap/core/runtime.h"

int main(int argc, char** argv) {
  vmap::RuntimeOptions runtime;
  // The runner keeps the default signal handling, so that Ctrl-C ends it at once; the interrupt tests
  // install vmap's in the child processes of their death tests.
  runtime.handle_interrupts = false;
  vmap::InitializeRuntime(runtime);
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
