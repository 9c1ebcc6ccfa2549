#pragma once
// Errors that reach the user. The message must name what is wrong (the file, the option) and how to fix it.

#include <exception>
#include <new>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace vmap {

// Bad input or bad options: the CLI prints the message and exits with status 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A bad option value, named by its field rather than by how it was given: the library has no command line
// (the CLI says the same with each field's flag, cli/option_flags.h). `path` is the field within the options
// struct that was checked ("extraction_threads", "key_images.tau"); `problem` says what is wrong with its value
// and how to fix it ("must be 0 to 256 (0 = one per core)"). The message is "<path> <problem>".
class OptionError : public InputError {
 public:
  // `others`: other fields of the struct holding `path` that `problem` names by their names (a check of two
  // fields), so that they can be named as the path is ("key_search" in "... and key_search bisect skips ...").
  OptionError(std::string path, std::string problem, std::vector<std::string> others = {})
      : InputError(path + " " + problem), path_(std::move(path)), problem_(std::move(problem)) {
    const std::string parent = Parent(path_);
    for (std::string& other : others) others_.push_back(parent + other);
  }

  const std::string& path() const { return path_; }
  const std::string& problem() const { return problem_; }
  // The paths of the fields `problem` names besides `path`; the text holds each by its last component.
  const std::vector<std::string>& others() const { return others_; }

  // The same error as a struct that holds the checked one as its field `field` sees it ("tau" -> "key_images.tau").
  OptionError Within(const std::string& field) const {
    OptionError error(field + "." + path_, problem_);
    for (const std::string& other : others_) error.others_.push_back(field + "." + other);
    return error;
  }

 private:
  static std::string Parent(const std::string& path) {
    const size_t dot = path.rfind('.');
    return dot == std::string::npos ? "" : path.substr(0, dot + 1);
  }

  std::string path_;
  std::string problem_;
  std::vector<std::string> others_;
};

// Runs `work()`; an OptionError from it is rethrown as the struct holding the checked one as `field` sees it.
template <typename Work>
auto NameOptionErrorsWithin(const std::string& field, Work&& work) -> decltype(work()) {
  try {
    return work();
  } catch (const OptionError& error) {
    throw error.Within(field);
  }
}

// Checks the nested options struct `options`, the field `field` of the one being checked: its errors name
// "field.<path>". MapBuilderOptions::Check() has CheckField("key_images", key_images).
template <typename Options>
void CheckField(const std::string& field, const Options& options) {
  NameOptionErrorsWithin(field, [&] { options.Check(); });
}

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
