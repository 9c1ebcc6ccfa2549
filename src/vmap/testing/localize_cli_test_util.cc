#include "vmap/testing/localize_cli_test_util.h"

#include <algorithm>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

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

}  // namespace vmap::testing
