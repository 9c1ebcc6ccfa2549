// vmap route MAP --from I --to J: the key images to follow from one key image to another.

#include <iostream>
#include <memory>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "vmap/cli/commands.h"
#include "vmap/cli/option_flags.h"
#include "vmap/cli/output_files.h"
#include "vmap/core/atomic_output.h"
#include "vmap/core/file_name_encoding.h"
#include "vmap/localization/route.h"
#include "vmap/map/map_io.h"

namespace vmap::cli {

namespace {

struct RouteFlags {
  std::string map;
  int from = 0;
  int to = -1;
  std::string json;
  RouteOptions options;
  OptionFlags option_flags;
};

void RunRoute(const RouteFlags& flags) {
  CheckOutputs({{flags.json, "--json"}}, {MapInputs(flags.map)});
  const VisualMap map = ReadMap(flags.map);
  const int to = flags.to >= 0 ? flags.to : static_cast<int>(map.key_images.size()) - 1;
  const Route route = PlanRoute(map, flags.from, to, flags.options);
  for (const std::string& warning : route.warnings) spdlog::warn("{}", warning);

  std::string keys;
  for (int k : route.keys) keys += (keys.empty() ? "" : " ") + std::to_string(k);
  std::cout << fmt::format("route           key {} -> key {}, {} steps\n", flags.from, to, route.steps.size())
            << "keys            " << keys << "\n";
  if (!route.steps.empty()) {
    std::cout << "\n| step | from key (frame) | to key (frame) | link | direction | S | verified | translation |\n"
              << "|---|---|---|---|---|---|---|---|\n";
  }
  nlohmann::json steps = nlohmann::json::array();
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
    steps.push_back({{"from", s.from_key},
                     {"to", s.to_key},
                     {"link", s.link},
                     {"backwards", s.backwards},
                     {"unverified", s.unverified},
                     {"similarity", l.similarity},
                     {"verified", l.num_verified},
                     {"translation_known", l.has_pose && l.translation_known},
                     {"translation_sigma_deg", l.translation_sigma_deg >= 0 ? nlohmann::json(l.translation_sigma_deg)
                                                                            : nlohmann::json(nullptr)}});
  }
  if (!flags.json.empty()) {
    // The map's path percent-encoded where it is not UTF-8, as in map.json (file_name_encoding.h).
    const nlohmann::json doc = {{"format", "vmap-route"},    {"map", EncodeFileName(flags.map)},
                                {"from", flags.from},        {"to", to},
                                {"keys", route.keys},        {"steps", steps},
                                {"warnings", route.warnings}};
    WriteFileAtomically(flags.json, doc.dump(1) + "\n");
  }
}

}  // namespace

void AddRouteCommand(CLI::App& app) {
  auto flags = std::make_shared<RouteFlags>();
  CLI::App* command = app.add_subcommand(
      "route", "The key images to follow from one key image to another (backwards when the links allow it)");
  command->add_option("map", flags->map, "Map directory written by `vmap build`")->required();
  command->add_option("--from", flags->from, "Start key image")->capture_default_str();
  command->add_option("--to", flags->to, "Goal key image (default: the last)");
  command->add_option("--json", flags->json, "Also write the route to this JSON file");
  flags->option_flags
      .AddOption(command, "--min-backward-verified", flags->options.min_backward_verified, "min_backward_verified",
                 "Verified matches a link needs to be followed backwards")
      ->capture_default_str();
  command->callback([flags] { flags->option_flags.Run([&] { RunRoute(*flags); }); });
}

}  // namespace vmap::cli
