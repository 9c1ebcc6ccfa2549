// vmap draw MAP_DIR --link K -o FILE: one match figure as an image file, for papers and slides.

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "vmap/cli/commands.h"
#include "vmap/cli/option_binder.h"
#include "vmap/core/atomic_output.h"
#include "vmap/core/contained_file.h"
#include "vmap/core/error.h"
#include "vmap/map/map_io.h"
#include "vmap/pipelines/output_policies.h"
#include "vmap/report/html_report.h"

namespace vmap::cli {
namespace {

struct DrawFlags {
  std::string map_directory;
  int link = 0;
  std::string output;
  MatchFigureOptions figure;  // --width, --no-caption
  OptionFlags option_flags;
};

void RunDraw(const DrawFlags& flags) {
  const std::filesystem::path output(flags.output);
  std::string extension = output.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension != ".png" && extension != ".jpg" && extension != ".jpeg") {
    throw InputError("output '" + flags.output + "' must end in .png, .jpg or .jpeg");
  }
  flags.figure.Check();
  // The figure must not overwrite what it is drawn from (the map's files).
  CheckOutputs({{flags.output, "-o"}}, {MapInputs(flags.map_directory)});
  const VisualMap map = ReadMap(flags.map_directory);
  const cv::Mat figure = DrawMapLink(flags.map_directory, map, flags.link, flags.figure);
  std::vector<uchar> encoded;
  const std::vector<int> parameters = extension == ".png" ? std::vector<int>{cv::IMWRITE_PNG_COMPRESSION, 6}
                                                          : std::vector<int>{cv::IMWRITE_JPEG_QUALITY, 92};
  if (!cv::imencode(extension, figure, encoded, parameters)) {
    throw InputError("cannot encode the figure as '" + extension + "'");
  }
  WriteFileAtomically(output, std::string_view(reinterpret_cast<const char*>(encoded.data()), encoded.size()));
  std::cout << "figure          " << output.string() << " (" << figure.cols << " x " << figure.rows << ")\n";
}

}  // namespace

void AddDrawCommand(CLI::App& app) {
  auto flags = std::make_shared<DrawFlags>();
  CLI::App* command = app.add_subcommand(
      "draw", "Draw one link's match figure (verified matches green, rejected blue) as a PNG or JPEG");
  command->add_option("map", flags->map_directory, "Map directory written by `vmap build`")->required();
  command->add_option("-l,--link", flags->link, "Link index: 0 joins the first two key images")
      ->required()
      ->check(CLI::NonNegativeNumber);
  command->add_option("-o,--output", flags->output, "Image file to write (.png, .jpg)")->required();
  AddOptionFlags(command, flags->figure, flags->option_flags);
  command->callback([flags] { flags->option_flags.Run([&] { RunDraw(*flags); }); });
}

}  // namespace vmap::cli
