#pragma once
// Reading XFeat weights in either layout users have, checking them key by key, and folding BatchNorm.
// Includes LibTorch: internal to vmap/neural.
//
// Layouts:
//   folded:   54 tensors, every convolution with a bias, BatchNorm folded in (../shared/weights/xfeat/
//             xfeat_folded.pt, the tensors of the published ONNX file);
//   official: upstream's `torch.save(model.state_dict())` (weights/xfeat.pt): the 23 BasicLayer convolutions
//             without bias, each followed by BatchNorm2d(affine=False) statistics (`<name>.layer.1.running_mean`,
//             `running_var`, `num_batches_tracked`), and the XFeat* refinement MLP `fine_matcher.*`, which the
//             sparse pipeline does not use and which is therefore not checked.

#include <string>

#include "vmap/neural/xfeat/xfeat_model.h"

namespace vmap::neural {

enum class XfeatLayout { kFolded, kOfficial };
std::string XfeatLayoutName(XfeatLayout layout);  // "folded" or "official"

// Reads a `torch.save` zip file holding a {name: tensor} dict (a plain dict or a collections.OrderedDict).
// Unreadable, truncated or foreign files throw InputError naming `path`.
StateDict ReadXfeatStateDict(const std::string& path);

// The layout `weights` has. Throws InputError listing the missing, unexpected and mis-shaped keys against the
// closer layout unless the file fits one exactly (fine_matcher.* aside).
XfeatLayout CheckXfeatStateDict(const StateDict& weights, const std::string& path);

// The folded tensors of official-layout weights: w' = w / sqrt(var + eps) per output channel and
// b' = -mean / sqrt(var + eps) (BatchNorm2d without affine parameters, eps 1e-5), computed in float64 and
// rounded once to float32. Weights already folded are returned as they are (fine_matcher.* dropped).
StateDict FoldXfeatBatchNorm(const StateDict& weights, XfeatLayout layout);

// One BasicLayer's folding: (w', b') from the bias-free conv weight and the BatchNorm statistics.
std::pair<torch::Tensor, torch::Tensor> FoldBatchNorm(const torch::Tensor& weight, const torch::Tensor& running_mean,
                                                      const torch::Tensor& running_var);

struct XfeatWeights {
  StateDict folded;  // what XfeatModel takes
  XfeatLayout layout = XfeatLayout::kFolded;
};
XfeatWeights LoadXfeatWeights(const std::string& path);  // read, check, fold

}  // namespace vmap::neural
