#include "vmap/testing/localize_cli_test_util.h"

#include <algorithm>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "vmap/testing/run_vmap.h"
#include "vmap/testing/shared_data.h"

namespace vmap::testing {

std::filesystem::path Shared() { return SharedDir(); }

std::vector<std::string> Lines(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::vector<std::string> CsvColumn(const std::filesystem::path& csv, const std::string& name) {
  auto split = [](const std::string& line) {
    std::vector<std::string> cells;
    std::stringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    if (!line.empty() && line.back() == ',') cells.emplace_back();
    return cells;
  };
  const std::vector<std::string> rows = Lines(csv);
  if (rows.empty()) return {};
  const std::vector<std::string> header = split(rows[0]);
  const size_t column = std::find(header.begin(), header.end(), name) - header.begin();
  EXPECT_LT(column, header.size()) << name << " is not a column of " << csv;
  std::vector<std::string> cells;
  for (size_t r = 1; r < rows.size(); ++r) {
    const std::vector<std::string> row = split(rows[r]);
    cells.push_back(column < row.size() ? row[column] : "");
  }
  return cells;
}

bool Placed(const std::pair<std::string, int>& frame) {
  return frame.first == "tracking" || frame.first == "relocalized";
}

std::vector<std::pair<int, int>> SteeredFrames(const std::string& args, const std::filesystem::path& csv) {
  const CliResult run = RunVmap("localize " + args + " -q --csv " + Quote(csv));
  EXPECT_EQ(run.status, 0) << run.output;
  const std::vector<std::string> status = CsvColumn(csv, "status"), source = CsvColumn(csv, "source_index"),
                                 key = CsvColumn(csv, "key");
  std::vector<std::pair<int, int>> steered;
  for (size_t f = 0; f < status.size(); ++f) {
    if (Placed({status[f], 0})) steered.emplace_back(std::stoi(source[f]), std::stoi(key[f]));
  }
  return steered;
}

}  // namespace vmap::testing
