#pragma once
// The flags of one command by the option fields they set. The library's checks name fields (OptionError:
// "extraction_threads must be 0 to 256"); the command says the same in its own words ("--threads must be 0 to
// 256"). Each flag records its field where it is bound (by the options' field lists: cli/option_binder.h; by hand
// for the few flags that are no field of an options struct), so the table cannot drift from the bindings.

#include <functional>
#include <map>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "vmap/core/error.h"

namespace vmap::cli {

// Throws InputError for an empty argument ("--csv ''", "--first=", a positional ''): CLI11 would read it as 0
// or as the default, and no option or path of vmap has an empty value. Checked once, for every command alike.
void RefuseEmptyArguments(int argc, const char* const* argv);

// Throws InputError naming the command when the first argument that is no flag is none of `commands` ("vmap
// buidl"): CLI11 would say only that a subcommand is required. The global options before it are flags alone.
void RefuseUnknownCommand(int argc, const char* const* argv, const std::vector<std::string>& commands);

// CLI11's message for `error` in vmap's words where it reads badly: a flag given twice ("--last is given 2 times;
// give it once", where CLI11 says "At Most 1 required but received 2"), and arguments not expected in the order they
// were given (CLI11 lists them backwards). Otherwise CLI11's own. `app`: the application that threw it.
std::string ParseErrorText(const CLI::ParseError& error, const CLI::App& app);

// The message of a thread that could not start (std::system_error, "Resource temporarily unavailable"): this
// user's process limit is reached. Other errors' own text.
std::string ThreadErrorMessage(const std::exception& error);

class OptionFlags {
 public:
  // `option` sets the field at `path` ("extraction_threads", "key_images.tau", "orb.num_features"), as the
  // struct the command checks names it. Returns `option`. A path recorded with two different flags is a
  // programming error (std::logic_error when the command is set up).
  CLI::Option* Record(const std::string& path, CLI::Option* option);
  void Record(const std::string& path, const std::string& flag);

  // Binds the flag `names` ("-t,--tau") to `field` and records it for `path`.
  template <typename T>
  CLI::Option* AddOption(CLI::App* command, const std::string& names, T& field, const std::string& path,
                         const std::string& help) {
    return Record(path, command->add_option(names, field, help));
  }
  CLI::Option* AddFlag(CLI::App* command, const std::string& names, bool& field, const std::string& path,
                       const std::string& help) {
    return Record(path, command->add_flag(names, field, help));
  }

  // The flag recorded for `path`, or "" when it has none.
  std::string FlagOf(const std::string& path) const;
  // The paths of the fields whose flags were given on the command line (after parsing).
  std::vector<std::string> Given() const;

  // `error`'s message with the flags of its path and of the other fields it names; a field without a flag
  // keeps its path.
  std::string Message(const OptionError& error) const;

  // Runs `run`; an OptionError from it comes out as an InputError in the flags' words.
  void Run(const std::function<void()>& run) const;

 private:
  std::map<std::string, std::string> flags_;           // field path -> flag
  std::map<std::string, const CLI::Option*> options_;  // field path -> its flag's option, where bound here
};

}  // namespace vmap::cli
