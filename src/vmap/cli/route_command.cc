// vmap route MAP --from I --to J: the route pipeline (pipelines/route_pipeline.h) and its table.

#include <iostream>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "vmap/cli/commands.h"
#include "vmap/cli/option_binder.h"
#include "vmap/pipelines/route_pipeline.h"

namespace vmap::cli {

namespace {

struct RouteCommand {
  RoutePipelineOptions options;
  OptionFlags flags;
};

void RunRoute(const RouteCommand& command) {
  const RoutePipelineResult result = RunRoutePipeline(command.options);
  const VisualMap& map = result.map;
  const Route& route = result.route;
  std::string keys;
  for (int k : route.keys) keys += (keys.empty() ? "" : " ") + std::to_string(k);
  std::cout << fmt::format("route           key {} -> key {}, {} steps\n", command.options.from, result.to,
                           route.steps.size())
            << "keys            " << keys << "\n";
  if (!route.steps.empty()) {
    std::cout << "\n| step | from key (frame) | to key (frame) | link | direction | S | verified | translation |\n"
              << "|---|---|---|---|---|---|---|---|\n";
  }
  for (size_t i = 0; i < route.steps.size(); ++i) {
    const RouteStep& s = route.steps[i];
    const Link& l = map.links[s.link];
    // A link followed backwards has the inverse pose; how well its translation is known is the same.
    const std::string translation =
        !l.has_pose ? "no pose"
                    : (l.translation_known ? "known" : "unknown: rotation only") +
                          (l.translation_sigma_deg >= 0 ? fmt::format(" ({:.1f} deg)", l.translation_sigma_deg) : "");
    std::cout << fmt::format("| {} | {} ({}) | {} ({}) | {} | {} | {:.3f} | {} | {} |\n", i, s.from_key,
                             map.key_images[s.from_key].frame_index, s.to_key, map.key_images[s.to_key].frame_index,
                             s.link, s.backwards ? "backwards" : (s.unverified ? "forwards, no F" : "forwards"),
                             l.similarity, l.num_verified, translation);
  }
}

}  // namespace

void AddRouteCommand(CLI::App& app) {
  auto state = std::make_shared<RouteCommand>();
  CLI::App* command = app.add_subcommand(
      "route", "The key images to follow from one key image to another (backwards when the links allow it)");
  AddOptionFlags(command, state->options, state->flags);
  command->callback([state] { state->flags.Run([&] { RunRoute(*state); }); });
}

}  // namespace vmap::cli
