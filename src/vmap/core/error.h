#pragma once
// Errors that reach the user. The message must name what is wrong (the file, the option) and how to fix it.

#include <exception>
#include <new>
#include <stdexcept>
#include <string>

namespace vmap {

// Bad input or bad options: the CLI prints the message and exits with status 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A library's exception text on one line (OpenCV's ends with a line break).
inline std::string LibraryMessage(const std::exception& error) {
  std::string text = error.what();
  text.erase(text.find_last_not_of(" \t\r\n") + 1);
  return text;
}

// What a stage was doing, on which file, and what the user can do about a failure.
struct ErrorContext {
  std::string what;  // "cannot decode frame 12 ('a.png')"
  std::string fix;   // "check the file"
};

// Runs `work()`. An exception from a library (OpenCV, LibTorch, nlohmann-json, std::filesystem, the standard
// library) becomes an InputError that says what failed, the library's own words in parentheses, and the fix:
// the stage that knows the file turns the error into vmap's. `describe()` returns the ErrorContext and is only
// called on failure, so a loop pays nothing for it. An InputError passes through unchanged.
template <typename Describe, typename Work>
auto RethrowAsInputError(Describe&& describe, Work&& work) -> decltype(work()) {
  try {
    return work();
  } catch (const InputError&) {
    throw;
  } catch (const std::bad_alloc&) {
    const ErrorContext context = describe();
    throw InputError(context.what + " (out of memory); " + context.fix);
  } catch (const std::exception& error) {
    const ErrorContext context = describe();
    throw InputError(context.what + " (" + LibraryMessage(error) + "); " + context.fix);
  }
}

}  // namespace vmap
