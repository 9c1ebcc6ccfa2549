#include "vmap/neural/xfeat/xfeat_weights.h"

#include <fstream>
#include <iterator>
#include <set>
#include <tuple>

#include <torch/serialize.h>

#include "vmap/core/error.h"
#include "vmap/neural/checkpoint_reader.h"

namespace vmap::neural {

namespace {

constexpr double kBatchNormEps = 1e-5;  // BatchNorm2d's default, used by every upstream BasicLayer
const char kFineMatcherPrefix[] = "fine_matcher.";

struct KeySpec {
  std::vector<int64_t> shape;
  bool floating = true;
};

std::map<std::string, KeySpec> ExpectedKeys(XfeatLayout layout) {
  std::map<std::string, KeySpec> keys;
  for (const XfeatConv& conv : XfeatConvolutions()) {
    keys[conv.weight_key()] = {{conv.out_channels, conv.in_channels, conv.kernel, conv.kernel}};
    if (conv.batch_norm && layout == XfeatLayout::kOfficial) {
      const std::string bn = conv.name + ".layer.1.";
      keys[bn + "running_mean"] = {{conv.out_channels}};
      keys[bn + "running_var"] = {{conv.out_channels}};
      keys[bn + "num_batches_tracked"] = {{}, false};
    } else {
      keys[conv.bias_key()] = {{conv.out_channels}};
    }
  }
  return keys;
}

std::string ShapeText(c10::IntArrayRef shape) {
  if (shape.empty()) return "scalar";
  std::string text;
  for (size_t i = 0; i < shape.size(); ++i) text += (i ? "x" : "") + std::to_string(shape[i]);
  return text;
}

struct Mismatch {
  std::vector<std::string> missing, unexpected, wrong_shape;
  size_t size() const { return missing.size() + unexpected.size() + wrong_shape.size(); }
};

Mismatch Compare(const StateDict& weights, XfeatLayout layout) {
  Mismatch result;
  const auto expected = ExpectedKeys(layout);
  for (const auto& [key, spec] : expected) {
    const auto it = weights.find(key);
    if (it == weights.end()) {
      result.missing.push_back(key);
    } else if (it->second.sizes().vec() != spec.shape || it->second.is_floating_point() != spec.floating) {
      result.wrong_shape.push_back(key + " (file " + std::string(c10::toString(it->second.scalar_type())) + " " +
                                   ShapeText(it->second.sizes()) + ", expected " +
                                   (spec.floating ? "float " : "integer ") + ShapeText(spec.shape) + ")");
    }
  }
  for (const auto& [key, tensor] : weights) {
    const bool fine_matcher = key.rfind(kFineMatcherPrefix, 0) == 0;
    if (!expected.count(key) && !(fine_matcher && layout == XfeatLayout::kOfficial)) result.unexpected.push_back(key);
  }
  return result;
}

std::string Describe(XfeatLayout layout) {
  return layout == XfeatLayout::kOfficial ? "the official layout (xfeat.pt: BatchNorm statistics, fine_matcher)"
                                          : "the folded layout (xfeat_folded.pt: BatchNorm folded into the convolutions)";
}

// torch.save(model.state_dict()) pickles a collections.OrderedDict, which LibTorch's unpickler cannot
// return; the checkpoint reader runs such files itself.
StateDict ReadWithCheckpointReader(const std::string& path, const std::string& first_error, size_t file_size) {
  StateDict weights = ReadRefusedWeightsFile(path, "XFeat", first_error, file_size);
  if (weights.empty()) throw InputError("XFeat weights file '" + path + "' holds no tensors");
  return weights;
}

}  // namespace

std::string XfeatLayoutName(XfeatLayout layout) { return layout == XfeatLayout::kOfficial ? "official" : "folded"; }

StateDict ReadXfeatStateDict(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError("cannot open XFeat weights file '" + path + "'; check the path given to --weights");
  const std::vector<char> bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  c10::IValue root;
  try {
    root = torch::pickle_load(bytes);
  } catch (const std::exception& e) {
    const std::string reason = e.what();
    return ReadWithCheckpointReader(path, reason.substr(0, reason.find('\n')), bytes.size());
  }
  if (root.isNone()) return ReadWithCheckpointReader(path, "OrderedDict", bytes.size());
  if (!root.isGenericDict()) {
    throw InputError("XFeat weights file '" + path + "' holds a " + root.tagKind() +
                     ", not a dict of tensors; see `vmap weights` for the supported files");
  }
  StateDict weights;
  for (const auto& entry : root.toGenericDict()) {
    if (!entry.key().isString() || !entry.value().isTensor()) {
      throw InputError("XFeat weights file '" + path + "': entry '" +
                       (entry.key().isString() ? entry.key().toStringRef() : entry.key().tagKind()) +
                       "' is not a named tensor; expected a state dict of tensors");
    }
    weights[entry.key().toStringRef()] = entry.value().toTensor();
  }
  if (weights.empty()) throw InputError("XFeat weights file '" + path + "' holds no tensors");
  return weights;
}

XfeatLayout CheckXfeatStateDict(const StateDict& weights, const std::string& path) {
  const Mismatch folded = Compare(weights, XfeatLayout::kFolded);
  if (folded.size() == 0) return XfeatLayout::kFolded;
  const Mismatch official = Compare(weights, XfeatLayout::kOfficial);
  if (official.size() == 0) {
    for (const XfeatConv& conv : XfeatConvolutions()) {
      if (!conv.batch_norm) continue;
      const std::string key = conv.name + ".layer.1.running_var";
      if (!(weights.at(key).min().item<double>() >= 0.0)) {
        throw InputError("XFeat weights file '" + path + "': " + key +
                         " has negative or NaN variances; the file is corrupt");
      }
    }
    return XfeatLayout::kOfficial;
  }
  const bool official_closer = official.size() < folded.size();
  const Mismatch& closest = official_closer ? official : folded;
  throw InputError("XFeat weights file '" + path + "' fits no XFeat layout; against " +
                   Describe(official_closer ? XfeatLayout::kOfficial : XfeatLayout::kFolded) + ":" +
                   ListStateDictKeys("missing keys", closest.missing) + ListStateDictKeys("unexpected keys", closest.unexpected) +
                   ListStateDictKeys("keys with another shape", closest.wrong_shape) +
                   "\n  Is it an XFeat file? See `vmap weights` for the supported files.");
}

std::pair<torch::Tensor, torch::Tensor> FoldBatchNorm(const torch::Tensor& weight, const torch::Tensor& running_mean,
                                                      const torch::Tensor& running_var) {
  const auto inverse_std = running_var.to(torch::kFloat64).add(kBatchNormEps).rsqrt();
  return {weight.to(torch::kFloat64).mul(inverse_std.view({-1, 1, 1, 1})).to(torch::kFloat32),
          running_mean.to(torch::kFloat64).neg().mul(inverse_std).to(torch::kFloat32)};
}

StateDict FoldXfeatBatchNorm(const StateDict& weights, XfeatLayout layout) {
  StateDict folded;
  for (const XfeatConv& conv : XfeatConvolutions()) {
    const torch::Tensor& weight = weights.at(conv.weight_key());
    if (!conv.batch_norm || layout == XfeatLayout::kFolded) {
      folded[conv.weight_key()] = weight.to(torch::kFloat32);
      folded[conv.bias_key()] = weights.at(conv.bias_key()).to(torch::kFloat32);
      continue;
    }
    const std::string bn = conv.name + ".layer.1.";
    std::tie(folded[conv.weight_key()], folded[conv.bias_key()]) =
        FoldBatchNorm(weight, weights.at(bn + "running_mean"), weights.at(bn + "running_var"));
  }
  return folded;
}

XfeatWeights LoadXfeatWeights(const std::string& path) {
  const StateDict weights = ReadXfeatStateDict(path);
  XfeatWeights out;
  out.layout = CheckXfeatStateDict(weights, path);
  out.folded = FoldXfeatBatchNorm(weights, out.layout);
  return out;
}

}  // namespace vmap::neural
