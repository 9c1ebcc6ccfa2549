// vmap build INPUT -o MAP_DIR: the build pipeline (pipelines/build_pipeline.h); with --add-experience-to MAP, the
// add-experience pipeline instead.

#include <iostream>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "vmap/cli/commands.h"
#include "vmap/cli/option_binder.h"
#include "vmap/cli/other_matcher_flags.h"
#include "vmap/core/error.h"
#include "vmap/pipelines/add_experience_pipeline.h"
#include "vmap/pipelines/build_pipeline.h"
#include "vmap/report/summary.h"

namespace vmap::cli {

namespace {

struct BuildCommand {
  BuildPipelineOptions build;
  AddExperiencePipelineOptions add;
  OptionFlags flags;
  std::vector<const CLI::Option*> acceptance;  // the repeat run's flags: they go with --add-experience-to only
  std::set<std::string> add_paths;             // the paths of the fields --add-experience-to reads
};

// The paths of the fields an options struct's flags set.
class FieldPaths final : public OptionFieldVisitor {
 public:
  std::set<std::string> paths;

 protected:
  void OnField(const OptionField& field, int& /*value*/) override { paths.insert(Path(field)); }
  void OnField(const OptionField& field, double& /*value*/) override { paths.insert(Path(field)); }
  void OnField(const OptionField& field, bool& /*value*/) override { paths.insert(Path(field)); }
  void OnField(const OptionField& field, std::string& /*value*/) override { paths.insert(Path(field)); }
  void OnField(const OptionField& field, std::vector<int>& /*value*/) override { paths.insert(Path(field)); }
  void OnField(const OptionField& field, const EnumField& /*value*/) override { paths.insert(Path(field)); }
  void OnField(const OptionField& field, std::optional<double>& /*value*/) override { paths.insert(Path(field)); }
};

// The flags given that set only how a map is built (its matcher's options, tau, the verifier, a mask): an experience
// is matched with the map's own options, and these were taken and ignored.
std::vector<std::string> BuildOnlyFlagsGiven(const BuildCommand& command) {
  std::set<std::string> read_by_add, build_only;
  const std::vector<std::string> given = command.flags.Given();
  for (const std::string& path : given) {
    if (command.add_paths.count(path) > 0) read_by_add.insert(command.flags.FlagOf(path));
  }
  for (const std::string& path : given) {
    const std::string flag = command.flags.FlagOf(path);
    if (!flag.empty() && read_by_add.count(flag) == 0) build_only.insert(flag);
  }
  return {build_only.begin(), build_only.end()};
}

// vmap build REPEAT --add-experience-to MAP: the input is localized against MAP and added as an experience.
void RunAddExperience(const BuildCommand& command) {
  const BuildPipelineOptions& build = command.build;
  if (!build.output.empty()) {
    throw InputError("--add-experience-to adds to the map it names; drop -o " + build.output);
  }
  if (build.snapshot_every > 0 || build.until_interrupted || build.report) {
    throw InputError(
        "--add-experience-to takes a whole recorded run; drop --snapshot-every, --until-interrupted "
        "and --report");
  }
  if (const std::vector<std::string> ignored = BuildOnlyFlagsGiven(command); !ignored.empty()) {
    throw InputError(
        fmt::format("{} set how a map is built; --add-experience-to matches the run with the map's own "
                    "options: drop {}",
                    fmt::join(ignored, ", "), ignored.size() == 1 ? "it" : "them"));
  }
  const AddExperienceSummary added = RunAddExperiencePipeline(command.add);
  std::cout << fmt::format("experience      {} of map {}\n", added.experience.id, command.add.map)
            << fmt::format("frames          {} ({} lost)\n", added.frames, added.lost)
            << fmt::format("views           {} of {} key images\n", added.experience.views.size(),
                           added.num_key_images);
}

void RunBuild(const BuildCommand& command) {
  if (!command.add.map.empty()) return RunAddExperience(command);
  for (const CLI::Option* flag : command.acceptance) {
    if (flag->count() > 0) {
      throw InputError(
          "--acceptance, --max-log10-nfa, --min-verified and --min-similarity say when a repeat run's "
          "frames localize; they go with --add-experience-to MAP");
    }
  }
  command.build.Check();  // a value out of range is said first
  RefuseOtherMatchersFlags(command.flags, command.build.matcher.type);
  const BuildPipelineResult built = RunBuildPipeline(command.build);
  std::cout << FormatMapSummary(built.map, command.build.map.quality_mean) << "map             "
            << built.directory.string() << "\n";
}

// The type and the values a localizer field takes as its flag's help shows them ("FLOAT in [-1000, 1000]"), from its
// declaration (LocalizerOptions::VisitFields): the flags below are bound by hand, with help of their own, but take
// the values the field declares.
std::string TypeWithRange(LocalizerOptions localizer, const std::string& key) {
  class Finder : public OptionFieldVisitor {
   public:
    explicit Finder(std::string key) : key_(std::move(key)) {}
    std::string found;

   protected:
    void OnField(const OptionField& field, int& /*value*/) override { Take(field, "INT", true); }
    void OnField(const OptionField& field, double& /*value*/) override { Take(field, "FLOAT", false); }
    void OnField(const OptionField& /*field*/, bool& /*value*/) override {}
    void OnField(const OptionField& /*field*/, std::string& /*value*/) override {}
    void OnField(const OptionField& /*field*/, std::vector<int>& /*value*/) override {}
    void OnField(const OptionField& /*field*/, const EnumField& /*value*/) override {}

   private:
    void Take(const OptionField& field, const char* type, bool integral) {
      if (Path(field) != key_ || !field.range.is_set) return;
      found = TypeWithValues(type, field.range, integral);
    }
    std::string key_;
  } finder(key);
  finder.VisitNested("", localizer);
  if (finder.found.empty()) throw std::logic_error("the localizer declares no range for " + key);
  return finder.found;
}

}  // namespace

void AddBuildCommand(CLI::App& app) {
  auto state = std::make_shared<BuildCommand>();
  CLI::App* command = app.add_subcommand("build", "Build a visual map from a video, image folder or dataset");
  // The build's options, then the add's: the input, --matcher and the input's options set both.
  OptionBinder binder;
  binder.Add("", state->build);
  binder.Add("", state->add, Nesting{false, {"experience"}});
  // --threads sets the repeat run's extraction threads too; the run's other flag is localize's alone.
  const Nesting run_threads{false, {"compare_ahead"}};
  binder.Add("experience.run", state->add.experience.run, run_threads);
  FieldPaths add_paths;
  add_paths.VisitNested("", state->add, Nesting{false, {"experience"}});
  add_paths.VisitNested("experience.run", state->add.experience.run, run_threads);
  binder.Bind(command, state->flags);
  // When a frame of the repeat run is seen at a key image, as `vmap localize` decides it (localize.md): four of
  // the localizer's options, with help that says they belong to --add-experience-to.
  LocalizerOptions& localizer = state->add.experience.localizer;
  OptionFlags& flags = state->flags;
  const auto read_by_add = [&add_paths](const char* path) { return *add_paths.paths.insert(path).first; };
  state->acceptance = {
      flags
          .Record(read_by_add("experience.localizer.acceptance"),
                  command->add_option_function<std::string>(
                      "--acceptance",
                      [&localizer](const std::string& rule) { localizer.acceptance = ParseAcceptanceRule(rule); },
                      "--add-experience-to: when a repeat frame is seen at a key image, as vmap localize "
                      "decides it: chance or counts"))
          ->default_str(AcceptanceRuleName(localizer.acceptance))
          ->group(kAddExperienceSection),
      flags
          .AddOption(command, "--max-log10-nfa", localizer.max_log10_nfa,
                     read_by_add("experience.localizer.max_log10_nfa"),
                     "--add-experience-to, --acceptance chance: accept when log10 of the number of false alarms "
                     "is at most this")
          ->type_name(TypeWithRange(localizer, "max_log10_nfa"))
          ->capture_default_str()
          ->group(kAddExperienceSection),
      flags
          .AddOption(command, "--min-verified", localizer.min_verified,
                     read_by_add("experience.localizer.min_verified"),
                     "--add-experience-to, --acceptance counts: verified matches a frame needs")
          ->type_name(TypeWithRange(localizer, "min_verified"))
          ->capture_default_str()
          ->group(kAddExperienceSection),
      flags
          .AddOption(command, "--min-similarity", localizer.min_similarity,
                     read_by_add("experience.localizer.min_similarity"),
                     "--add-experience-to, --acceptance counts: S a frame needs")
          ->type_name(TypeWithRange(localizer, "min_similarity"))
          ->capture_default_str()
          ->group(kAddExperienceSection)};
  state->add_paths = std::move(add_paths.paths);
  command->callback([state] { state->flags.Run([&] { RunBuild(*state); }); });
}

}  // namespace vmap::cli
