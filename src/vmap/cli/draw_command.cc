// vmap draw MAP_DIR --link K -o FILE: one match figure as an image file, for papers and slides
// (pipelines/draw_pipeline.h).

#include <iostream>
#include <memory>

#include "vmap/cli/commands.h"
#include "vmap/cli/option_binder.h"
#include "vmap/pipelines/draw_pipeline.h"

namespace vmap::cli {
namespace {

struct DrawFlags {
  DrawPipelineOptions options;
  OptionFlags option_flags;
};

void RunDraw(const DrawFlags& flags) {
  const cv::Size size = RunDrawPipeline(flags.options);
  std::cout << "figure          " << flags.options.output << " (" << size.width << " x " << size.height << ")\n";
}

}  // namespace

void AddDrawCommand(CLI::App& app) {
  auto flags = std::make_shared<DrawFlags>();
  CLI::App* command = app.add_subcommand(
      "draw", "Draw one link's match figure (verified matches green, rejected blue) as a PNG or JPEG");
  AddOptionFlags(command, flags->options, flags->option_flags);
  // No default link or file: a figure is drawn of the link asked for, into the file named.
  command->get_option("--link")->required();
  command->get_option("--output")->required();
  command->callback([flags] { flags->option_flags.Run([&] { RunDraw(*flags); }); });
}

}  // namespace vmap::cli
