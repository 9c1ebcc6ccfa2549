#pragma once
// Test helpers for comparing the port with the upstream reference in ../shared/golden.

#include <filesystem>
#include <map>
#include <string>

#include <nlohmann/json.hpp>
#include <torch/torch.h>

#include "vmap/testing/run_vmap.h"
#include "vmap/testing/scoped_temp_dir.h"
#include "vmap/testing/shared_data.h"

namespace vmap::neural::testing {

std::map<std::string, torch::Tensor> LoadTensorDict(const std::string& path);
nlohmann::json LoadJson(const std::string& path);
// cv::imread(GRAYSCALE) as the network input tensor (1, 1, H, W) = uint8 / 255.
torch::Tensor ReadNetworkInput(const std::string& png);

// max |actual - expected| - (atol + rtol |expected|); <= 0 means within tolerance.
double ExcessOverTolerance(const torch::Tensor& actual, const torch::Tensor& expected, double atol, double rtol);
double MaxAbsDiff(const torch::Tensor& actual, const torch::Tensor& expected);

// The torch-free helpers (shared data, temporary folders, running the binary) live in vmap_testing.
using vmap::testing::CliResult;
using vmap::testing::RunVmap;
using vmap::testing::ScopedTempDir;
using vmap::testing::SharedDataPresent;
using vmap::testing::SharedDir;

}  // namespace vmap::neural::testing

// Asserts shapes match and every element is within atol + rtol * |expected|.
#define EXPECT_TENSOR_NEAR(actual, expected, atol, rtol)                                                   \
  do {                                                                                                     \
    auto _a = (actual).detach().to(torch::kCPU).to(torch::kFloat64);                                      \
    auto _e = (expected).detach().to(torch::kCPU).to(torch::kFloat64);                                    \
    ASSERT_EQ(_a.sizes(), _e.sizes()) << #actual;                                                         \
    EXPECT_LE(::vmap::neural::testing::ExcessOverTolerance(_a, _e, atol, rtol), 0.0)                      \
        << #actual << " vs " << #expected << ": max |diff| " << ::vmap::neural::testing::MaxAbsDiff(_a, _e); \
  } while (0)
