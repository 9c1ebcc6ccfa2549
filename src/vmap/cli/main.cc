// vmap: builds visual maps (key images linked by fundamental matrices) from teach-run videos.

#include <cstdio>
#include <exception>

#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>

#include "vmap/cli/commands.h"
#include "vmap/core/error.h"
#include "vmap/core/logging.h"

int main(int argc, char** argv) {
  CLI::App app{"vmap: visual maps for vision-only robot navigation (key images linked by fundamental matrices)"};
  app.set_version_flag("--version", std::string("vmap ") + VMAP_VERSION);
  app.require_subcommand(1);
  app.fallthrough();  // global flags may follow the subcommand
  bool verbose = false, quiet = false;
  app.add_flag("-v,--verbose", verbose, "Log every decision (debug level)");
  app.add_flag("-q,--quiet", quiet, "Only warnings and errors; no progress line");
  app.parse_complete_callback([&] { vmap::ConfigureLogging(quiet ? "quiet" : verbose ? "debug" : "info"); });

  vmap::cli::AddBuildCommand(app);
  vmap::cli::AddInfoCommand(app);
  vmap::cli::AddSweepCommand(app);
  vmap::cli::AddMatchCommand(app);
  vmap::cli::AddWeightsCommand(app);
  vmap::cli::AddReportCommand(app);
  vmap::cli::AddDrawCommand(app);
  vmap::cli::AddEvalCommand(app);

  // vmap runs frames in parallel itself; OpenCV's own threads inside ORB then only add contention
  // (measured: 5.1 ms per 640x480 frame on one thread, 7.2 ms with two).
  cv::setNumThreads(1);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const vmap::InputError& e) {
    std::fprintf(stderr, "vmap: error: %s\n", e.what());
    return 2;
  } catch (const cv::Exception& e) {
    std::fprintf(stderr, "vmap: OpenCV error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "vmap: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
