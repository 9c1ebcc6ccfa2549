#include "vmap/neural/golden_util.h"

#include <filesystem>
#include <fstream>
#include <iterator>

#include <sys/wait.h>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>
#include <torch/serialize.h>

namespace vmap::neural::testing {

std::string SharedDir() { return VMAP_SHARED_DIR; }

bool SharedDataPresent() { return std::filesystem::is_directory(SharedDir() + "/golden"); }

std::map<std::string, torch::Tensor> LoadTensorDict(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw std::runtime_error("cannot open " + path);
  std::vector<char> bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  std::map<std::string, torch::Tensor> out;
  for (const auto& entry : torch::pickle_load(bytes).toGenericDict()) {
    out[entry.key().toStringRef()] = entry.value().toTensor();
  }
  return out;
}

nlohmann::json LoadJson(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw std::runtime_error("cannot open " + path);
  // Python's json writes Infinity/NaN, which are not JSON; the tests never read those fields.
  std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  for (const std::string token : {"-Infinity", "Infinity", "NaN"}) {
    for (size_t at; (at = text.find(token)) != std::string::npos;) text.replace(at, token.size(), "null");
  }
  return nlohmann::json::parse(text);
}

torch::Tensor ReadNetworkInput(const std::string& png) {
  cv::Mat gray = cv::imread(png, cv::IMREAD_GRAYSCALE);
  if (gray.empty()) throw std::runtime_error("cannot read " + png);
  auto bytes = torch::from_blob(gray.data, {1, 1, gray.rows, gray.cols}, torch::kUInt8).clone();
  return bytes.to(torch::kFloat32) / 255.0;
}

double ExcessOverTolerance(const torch::Tensor& actual, const torch::Tensor& expected, double atol, double rtol) {
  if (actual.numel() == 0) return 0.0;
  auto excess = (actual - expected).abs() - (atol + rtol * expected.abs());
  return excess.max().item<double>();
}

double MaxAbsDiff(const torch::Tensor& actual, const torch::Tensor& expected) {
  if (actual.numel() == 0) return 0.0;
  return (actual - expected).abs().max().item<double>();
}

CliResult RunVmap(const std::string& arguments, const std::string& environment) {
  const std::string command = environment + std::string(VMAP_BINARY) + " " + arguments + " 2>&1";
  CliResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return result;
  char buffer[4096];
  while (size_t n = fread(buffer, 1, sizeof(buffer), pipe)) result.output.append(buffer, n);
  const int status = pclose(pipe);
  result.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

ScopedTempDir::ScopedTempDir(const std::string& name)
    : path_(std::filesystem::temp_directory_path() /
            ("vmap_neural_test_" + std::to_string(getpid()) + "_" + name)) {
  std::filesystem::remove_all(path_);
  std::filesystem::create_directories(path_);
}

ScopedTempDir::~ScopedTempDir() {
  std::error_code error;
  std::filesystem::remove_all(path_, error);
}

}  // namespace vmap::neural::testing
