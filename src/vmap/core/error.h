#pragma once
// Errors that reach the user. The message must name what is wrong (the file, the option) and how to fix it.

#include <stdexcept>
#include <string>

namespace vmap {

// Bad input or bad options: the CLI prints the message and exits with status 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace vmap
