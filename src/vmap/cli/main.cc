// vmap: builds visual maps (key images linked by fundamental matrices) from teach-run videos.

#include <csignal>
#include <cstdio>
#include <exception>
#include <initializer_list>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>

#include "vmap/cli/commands.h"
#include "vmap/cli/decimal_integers.h"
#include "vmap/cli/help_formatter.h"
#include "vmap/cli/option_flags.h"
#include "vmap/core/error.h"
#include "vmap/core/logging.h"
#include "vmap/core/runtime.h"
#include "vmap/core/temporary_name.h"
#include "vmap/core/terminal_text.h"

int main(int argc, char** argv) {
  // A file beyond `ulimit -f` and a reader gone away (`vmap ... | head`) are then errors of the write that met them,
  // so that the command says so and removes its unfinished outputs: by default either signal kills it silently.
  std::signal(SIGXFSZ, SIG_IGN);
  std::signal(SIGPIPE, SIG_IGN);
  // First, while this is the only thread: signal handling (an interrupted command removes its unfinished
  // outputs and exits with 128 + the signal), OpenCV's threads, malloc, FFmpeg's log (see runtime.h).
  try {
    vmap::InitializeRuntime();
  } catch (const std::exception& e) {  // a thread that cannot start (the process limit reached)
    std::fprintf(stderr, "vmap: error: %s\n", vmap::cli::ThreadErrorMessage(e).c_str());
    return 2;
  }
  CLI::App app{"vmap: visual maps for vision-only robot navigation (key images linked by fundamental matrices)",
               "vmap"};
  app.formatter(std::make_shared<vmap::cli::HelpFormatter>());  // before the commands: each takes it on
  app.set_version_flag("--version", std::string("vmap ") + VMAP_VERSION);
  app.require_subcommand(1);
  app.fallthrough();  // global flags may follow the subcommand
  bool verbose = false, quiet = false;
  app.add_flag("-v,--verbose", verbose, "Log every decision (debug level)");
  app.add_flag("-q,--quiet", quiet, "Only warnings and errors; no progress line");
  app.parse_complete_callback([&] { vmap::ConfigureLogging(quiet ? "quiet" : verbose ? "debug" : "info"); });

  // `vmap --help` lists the commands under these headings, in this order: the teach-and-repeat workflow first.
  const auto add = [&app](const char* heading, std::initializer_list<void (*)(CLI::App&)> commands) {
    for (const auto command : commands) {
      command(app);
      app.get_subcommands({}).back()->group(heading);
    }
  };
  add("Teach and repeat", {vmap::cli::AddBuildCommand, vmap::cli::AddLocalizeCommand, vmap::cli::AddRouteCommand,
                           vmap::cli::AddSimulateCommand});
  add("Look into a map, a run or an image pair",
      {vmap::cli::AddInfoCommand, vmap::cli::AddReportCommand, vmap::cli::AddEvalCommand, vmap::cli::AddSweepCommand,
       vmap::cli::AddMatchCommand, vmap::cli::AddDrawCommand});
  add("Set up", {vmap::cli::AddWeightsCommand});
  vmap::cli::ReadIntegerFlagsAsDecimal(app);

  // `vmap` alone lists the commands, as `colmap` and `git` do: a first try is not an error.
  if (argc == 1) {
    std::fputs(app.help().c_str(), stdout);
    return 0;
  }
  // Every failure ends as "vmap: error: ..." with status 2; 0 is success, --help and --version included.
  try {
    vmap::cli::RefuseEmptyArguments(argc, argv);
    std::vector<std::string> commands;
    for (const CLI::App* command : app.get_subcommands({})) commands.push_back(command->get_name());
    vmap::cli::RefuseUnknownCommand(argc, argv, commands);
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);  // --help, --version
    std::fprintf(stderr, "vmap: error: %s; see `vmap --help` or `vmap COMMAND --help`\n",
                 vmap::TerminalSafe(vmap::cli::ParseErrorText(e, app)).c_str());
    return 2;
  } catch (const vmap::InputError& e) {
    std::fprintf(stderr, "vmap: error: %s\n", vmap::TerminalSafe(vmap::NameOutputsNotTemporaries(e.what())).c_str());
    return 2;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "vmap: error: out of memory; try a smaller input or smaller options (--resize)\n");
    return 2;
  } catch (const std::length_error&) {  // a size no allocation could take: out of memory all the same
    std::fprintf(stderr, "vmap: error: out of memory; try a smaller input or smaller options (--resize)\n");
    return 2;
  } catch (const cv::Exception& e) {
    if (e.code == cv::Error::StsNoMem) {  // OpenCV's own allocator failed ("Insufficient memory")
      std::fprintf(stderr, "vmap: error: out of memory; try a smaller input or smaller options (--resize)\n");
    } else {
      std::fprintf(stderr, "vmap: error: %s (an unexpected error: please report it)\n",
                   vmap::TerminalSafe(vmap::LibraryMessage(e)).c_str());
    }
    return 2;
  } catch (const std::system_error& e) {
    if (e.code() != std::errc::resource_unavailable_try_again) {
      std::fprintf(stderr, "vmap: error: %s (an unexpected error: please report it)\n",
                   vmap::TerminalSafe(e.what()).c_str());
    } else {
      std::fprintf(stderr, "vmap: error: %s\n", vmap::cli::ThreadErrorMessage(e).c_str());
    }
    return 2;
  } catch (const std::exception& e) {
    // A library error that no stage turned into vmap's: still an error message, and a bug to report.
    std::fprintf(stderr, "vmap: error: %s (an unexpected error: please report it)\n",
                 vmap::TerminalSafe(e.what()).c_str());
    return 2;
  }
  return 0;
}
