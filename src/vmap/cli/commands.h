#pragma once
// The subcommands of the `vmap` binary. Each Add*Command registers one subcommand on the app.

#include <CLI/CLI.hpp>

namespace vmap::cli {

void AddBuildCommand(CLI::App& app);
void AddInfoCommand(CLI::App& app);
void AddSweepCommand(CLI::App& app);
void AddMatchCommand(CLI::App& app);
void AddWeightsCommand(CLI::App& app);
void AddReportCommand(CLI::App& app);
void AddDrawCommand(CLI::App& app);
void AddEvalCommand(CLI::App& app);
void AddLocalizeCommand(CLI::App& app);
void AddRouteCommand(CLI::App& app);
void AddSimulateCommand(CLI::App& app);

}  // namespace vmap::cli
