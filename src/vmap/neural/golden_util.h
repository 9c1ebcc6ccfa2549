#pragma once
// Test helpers for comparing the port with the upstream reference in ../shared/golden.

#include <filesystem>
#include <map>
#include <string>

#include <nlohmann/json.hpp>
#include <torch/torch.h>

namespace vmap::neural::testing {

std::string SharedDir();                   // VMAP_SHARED_DIR
bool SharedDataPresent();                  // ../shared/golden exists
std::map<std::string, torch::Tensor> LoadTensorDict(const std::string& path);
nlohmann::json LoadJson(const std::string& path);
// cv::imread(GRAYSCALE) as the network input tensor (1, 1, H, W) = uint8 / 255.
torch::Tensor ReadNetworkInput(const std::string& png);

// max |actual - expected| - (atol + rtol |expected|); <= 0 means within tolerance.
double ExcessOverTolerance(const torch::Tensor& actual, const torch::Tensor& expected, double atol, double rtol);
double MaxAbsDiff(const torch::Tensor& actual, const torch::Tensor& expected);

// The vmap binary (VMAP_BINARY) run with `arguments`; `environment` is prepended (VAR=value ...). Output is
// stdout and stderr together.
struct CliResult {
  int status = -1;  // exit status; -1 when it did not exit normally
  std::string output;
};
CliResult RunVmap(const std::string& arguments, const std::string& environment = "");

// A fresh folder under the system's temporary folder, removed with everything in it at the end of its scope.
class ScopedTempDir {
 public:
  explicit ScopedTempDir(const std::string& name);
  ~ScopedTempDir();
  ScopedTempDir(const ScopedTempDir&) = delete;
  ScopedTempDir& operator=(const ScopedTempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace vmap::neural::testing

#define SKIP_WITHOUT_SHARED()                                          \
  if (!::vmap::neural::testing::SharedDataPresent())                   \
  GTEST_SKIP() << "no shared data at " << ::vmap::neural::testing::SharedDir() << "/golden"

// Asserts shapes match and every element is within atol + rtol * |expected|.
#define EXPECT_TENSOR_NEAR(actual, expected, atol, rtol)                                                   \
  do {                                                                                                     \
    auto _a = (actual).detach().to(torch::kCPU).to(torch::kFloat64);                                      \
    auto _e = (expected).detach().to(torch::kCPU).to(torch::kFloat64);                                    \
    ASSERT_EQ(_a.sizes(), _e.sizes()) << #actual;                                                         \
    EXPECT_LE(::vmap::neural::testing::ExcessOverTolerance(_a, _e, atol, rtol), 0.0)                      \
        << #actual << " vs " << #expected << ": max |diff| " << ::vmap::neural::testing::MaxAbsDiff(_a, _e); \
  } while (0)
