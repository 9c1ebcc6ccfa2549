#include "vmap/testing/golden_util.h"

#include <fstream>
#include <iterator>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <torch/serialize.h>

#include "vmap/core/error.h"

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

std::string ExpectInputError(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected InputError";
  return "";
}

void WriteBytes(const std::string& path, const std::vector<char>& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

void PickleProgram::String(const std::string& s) {
  Op('X');
  Int32(static_cast<uint32_t>(s.size()));
  code_ += s;
}

void PickleProgram::Int(int64_t v) {
  Op('J');
  Int32(static_cast<uint32_t>(v));
}

void PickleProgram::Int32(uint32_t v) {
  for (int i = 0; i < 4; ++i) code_ += static_cast<char>((v >> (8 * i)) & 0xff);
}

void PickleProgram::Tensor(const torch::Tensor& t, const std::string& record) {
  Global("torch._utils", "_rebuild_tensor_v2");
  Op('(');
  Op('(');
  String("storage");
  Global("torch", t.scalar_type() == torch::kInt64 ? "LongStorage" : "FloatStorage");
  String(record);
  String("cpu");
  Int(t.numel());
  Op('t');
  Op('Q');
  Int(0);  // storage offset
  Op('(');
  for (auto d : t.sizes()) Int(d);
  Op('t');
  Op('(');
  for (auto d : t.strides()) Int(d);
  Op('t');
  Op('\x89');                            // requires_grad False
  Global("collections", "OrderedDict");  // backward hooks
  Op(')');
  Op('R');
  Op('t');
  Op('R');
}

void PickleProgram::OrderedStateDict(const StateDict& weights, const std::string& key_prefix, int first_record,
                                     caffe2::serialize::PyTorchStreamWriter& writer) {
  Global("collections", "OrderedDict");
  Op(')');
  Op('R');
  Op('(');
  int record = first_record;
  for (const auto& [key, tensor] : weights) {
    const torch::Tensor contiguous = tensor.contiguous();
    String(key_prefix + key);
    Tensor(contiguous, std::to_string(record));
    writer.writeRecord("data/" + std::to_string(record), contiguous.data_ptr(),
                       contiguous.numel() * contiguous.element_size());
    ++record;
  }
  Op('u');
  Op('}');  // the OrderedDict's attributes: {'_metadata': OrderedDict()}
  String("_metadata");
  Global("collections", "OrderedDict");
  Op(')');
  Op('R');
  Op('s');
  Op('b');
}

void WriteOrderedDictFile(const StateDict& weights, const std::string& path) {
  caffe2::serialize::PyTorchStreamWriter writer(path);
  PickleProgram program;
  program.Raw("\x80\x02");
  program.OrderedStateDict(weights, "", 0, writer);
  program.Op('.');
  writer.writeRecord("data.pkl", program.code().data(), program.code().size());
  writer.writeEndOfFile();
}

}  // namespace vmap::neural::testing
