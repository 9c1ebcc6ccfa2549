#pragma once
// Test helpers of the neural tests: comparing the port with the upstream reference in ../shared/golden, and
// writing weights files the way Python's torch.save does.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <caffe2/serialize/inline_container.h>
#include <nlohmann/json.hpp>
#include <torch/torch.h>

#include "vmap/neural/state_dict.h"
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

// Runs `f` and returns the message of the InputError it throws; a test failure when it throws none.
std::string ExpectInputError(const std::function<void()>& f);
void WriteBytes(const std::string& path, const std::vector<char>& bytes);

// A pickle program written opcode by opcode, for files LibTorch's own writer cannot make: Python objects such
// as collections.OrderedDict or classes LibTorch does not know.
class PickleProgram {
 public:
  void Raw(const std::string& bytes) { code_ += bytes; }
  void Op(char op) { code_ += op; }
  void String(const std::string& s);
  void Int(int64_t v);
  void Global(const std::string& module, const std::string& name) { code_ += "c" + module + "\n" + name + "\n"; }
  // torch._utils._rebuild_tensor_v2 of a contiguous `t` whose bytes are the archive's record data/<record>.
  void Tensor(const torch::Tensor& t, const std::string& record);
  // The collections.OrderedDict {key_prefix + key: tensor} with the _metadata attribute torch.save gives it;
  // the tensors' bytes are written to `writer` as records data/<first_record>, data/<first_record + 1>, ...
  void OrderedStateDict(const StateDict& weights, const std::string& key_prefix, int first_record,
                        caffe2::serialize::PyTorchStreamWriter& writer);
  const std::string& code() const { return code_; }

 private:
  void Int32(uint32_t v);
  std::string code_;
};

// Writes `weights` as torch.save(model.state_dict(), path) does in Python: the root object is a
// collections.OrderedDict, which LibTorch's own unpickler cannot build.
void WriteOrderedDictFile(const StateDict& weights, const std::string& path);

// The torch-free helpers (shared data, temporary folders, running the binary) live in vmap_testing.
using vmap::testing::CliResult;
using vmap::testing::RunVmap;
using vmap::testing::ScopedTempDir;
using vmap::testing::SharedDataPresent;
using vmap::testing::SharedDir;

}  // namespace vmap::neural::testing

// Asserts shapes match and every element is within atol + rtol * |expected|.
#define EXPECT_TENSOR_NEAR(actual, expected, atol, rtol)                                                     \
  do {                                                                                                       \
    auto _a = (actual).detach().to(torch::kCPU).to(torch::kFloat64);                                         \
    auto _e = (expected).detach().to(torch::kCPU).to(torch::kFloat64);                                       \
    ASSERT_EQ(_a.sizes(), _e.sizes()) << #actual;                                                            \
    EXPECT_LE(::vmap::neural::testing::ExcessOverTolerance(_a, _e, atol, rtol), 0.0)                         \
        << #actual << " vs " << #expected << ": max |diff| " << ::vmap::neural::testing::MaxAbsDiff(_a, _e); \
  } while (0)
