#include "vmap/neural/xfeat/xfeat_weights.h"

#include <algorithm>
#include <tuple>

#include "vmap/core/error.h"

namespace vmap::neural {

namespace {

constexpr double kBatchNormEps = 1e-5;  // BatchNorm2d's default, used by every upstream BasicLayer
const char kFineMatcherPrefix[] = "fine_matcher.";

std::vector<TensorSpec> ExpectedTensors(XfeatLayout layout) {
  std::vector<TensorSpec> tensors;
  for (const XfeatConv& conv : XfeatConvolutions()) {
    tensors.push_back({conv.weight_key(), "float32", {conv.out_channels, conv.in_channels, conv.kernel, conv.kernel}});
    if (conv.batch_norm && layout == XfeatLayout::kOfficial) {
      const std::string bn = conv.name + ".layer.1.";
      tensors.push_back({bn + "running_mean", "float32", {conv.out_channels}});
      tensors.push_back({bn + "running_var", "float32", {conv.out_channels}});
      tensors.push_back({bn + "num_batches_tracked", "int64", {}});
    } else {
      tensors.push_back({conv.bias_key(), "float32", {conv.out_channels}});
    }
  }
  return tensors;
}

StateDictMismatch Compare(const StateDict& weights, XfeatLayout layout) {
  StateDictMismatch result = CompareStateDict(weights, ExpectedTensors(layout));
  // The official file also holds the fine matcher, which vmap does not use.
  if (layout == XfeatLayout::kOfficial) {
    auto& unexpected = result.unexpected;
    unexpected.erase(std::remove_if(unexpected.begin(), unexpected.end(),
                                    [](const std::string& key) { return key.rfind(kFineMatcherPrefix, 0) == 0; }),
                     unexpected.end());
  }
  return result;
}

std::string Describe(XfeatLayout layout) {
  return layout == XfeatLayout::kOfficial
             ? "the official layout (xfeat.pt: BatchNorm statistics, fine_matcher)"
             : "the folded layout (xfeat_folded.pt: BatchNorm folded into the convolutions)";
}

}  // namespace

std::string XfeatLayoutName(XfeatLayout layout) { return layout == XfeatLayout::kOfficial ? "official" : "folded"; }

StateDict ReadXfeatStateDict(const std::string& path) { return ReadWeightsFile(path, "XFeat"); }

XfeatLayout CheckXfeatStateDict(const StateDict& weights, const std::string& path) {
  const StateDictMismatch folded = Compare(weights, XfeatLayout::kFolded);
  if (folded.empty()) return XfeatLayout::kFolded;
  const StateDictMismatch official = Compare(weights, XfeatLayout::kOfficial);
  if (official.empty()) {
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
  const StateDictMismatch& closest = official_closer ? official : folded;
  throw InputError("XFeat weights file '" + path + "' fits no XFeat layout; against " +
                   Describe(official_closer ? XfeatLayout::kOfficial : XfeatLayout::kFolded) + ":" +
                   closest.Describe() + "\n  Is it an XFeat file? See `vmap weights` for the supported files.");
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
