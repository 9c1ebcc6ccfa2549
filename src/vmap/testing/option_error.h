#pragma once
// What a check says when it refuses: the field an options check names, the message of an InputError.

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

// The message of the InputError `work()` throws; "" when it throws none.
template <typename Work>
std::string InputErrorMessage(Work&& work) {
  try {
    work();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

}  // namespace vmap::testing
