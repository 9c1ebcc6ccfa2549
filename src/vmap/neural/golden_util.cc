#include "vmap/neural/golden_util.h"

#include <fstream>
#include <iterator>

#include <opencv2/imgcodecs.hpp>
#include <torch/serialize.h>

namespace vmap::neural::testing {

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

}  // namespace vmap::neural::testing
