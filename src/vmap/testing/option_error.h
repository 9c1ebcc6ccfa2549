#pragma once
// The field an options check names when it refuses a value.

#include <exception>
#include <string>

#include <gtest/gtest.h>

#include "vmap/core/error.h"

namespace vmap::testing {

// The path of the OptionError `check()` throws; "" (and a test failure) when it throws none or another error.
template <typename Check>
std::string OptionErrorPath(Check&& check) {
  try {
    check();
  } catch (const OptionError& error) {
    return error.path();
  } catch (const std::exception& error) {
    ADD_FAILURE() << "not an OptionError: " << error.what();
    return "";
  }
  ADD_FAILURE() << "no OptionError";
  return "";
}

}  // namespace vmap::testing
