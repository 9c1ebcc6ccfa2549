#include "vmap/neural/aliked/aliked_config.h"

#include "vmap/core/error.h"

namespace vmap::neural {

namespace {

void AddBatchNorm(std::vector<TensorSpec>& specs, const std::string& prefix, int64_t channels) {
  for (const char* name : {".weight", ".bias", ".running_mean", ".running_var"}) {
    specs.push_back({prefix + name, "float32", {channels}});
  }
  specs.push_back({prefix + ".num_batches_tracked", "int64", {}});
}

void AddConv(std::vector<TensorSpec>& specs, const std::string& prefix, int64_t out, int64_t in, int64_t kernel,
             bool bias) {
  specs.push_back({prefix + ".weight", "float32", {out, in, kernel, kernel}});
  if (bias) specs.push_back({prefix + ".bias", "float32", {out}});
}

// A 3x3 convolution without bias, plain or deformable (offsets predicted by a 3x3 convolution with bias:
// 2 x 9 channels, one (dy, dx) per kernel tap).
void AddBlockConv(std::vector<TensorSpec>& specs, const std::string& prefix, int64_t out, int64_t in, bool deformable) {
  if (deformable) {
    AddConv(specs, prefix + ".offset_conv", 2 * 3 * 3, in, 3, true);
    AddConv(specs, prefix + ".regular_conv", out, in, 3, false);
  } else {
    AddConv(specs, prefix, out, in, 3, false);
  }
}

void AddBlock(std::vector<TensorSpec>& specs, const std::string& name, int64_t in, int64_t out, bool deformable,
              bool residual) {
  AddBlockConv(specs, name + ".conv1", out, in, deformable);
  AddBatchNorm(specs, name + ".bn1", out);
  AddBlockConv(specs, name + ".conv2", out, out, deformable);
  AddBatchNorm(specs, name + ".bn2", out);
  if (residual) AddConv(specs, name + ".downsample", out, in, 1, true);
}

}  // namespace

const std::vector<std::string>& AlikedPresetNames() {
  static const std::vector<std::string> names{"t16", "n16"};
  return names;
}

AlikedConfig AlikedPreset(const std::string& name) {
  const std::string key = name.rfind("aliked-", 0) == 0 ? name.substr(7) : name;
  AlikedConfig config;
  config.name = key;
  if (key == "t16") {
    config.c1 = 8, config.c2 = 16, config.c3 = 32, config.c4 = 64, config.dim = 64;
  } else if (key == "n16") {
    config.c1 = 16, config.c2 = 32, config.c3 = 64, config.c4 = 128, config.dim = 128;
  } else {
    throw InputError("unknown ALIKED model '" + name + "'; use t16 or n16");
  }
  return config;
}

std::vector<TensorSpec> AlikedExpectedStateDict(const AlikedConfig& c) {
  std::vector<TensorSpec> specs;
  AddBlock(specs, "block1", 3, c.c1, /*deformable=*/false, /*residual=*/false);
  AddBlock(specs, "block2", c.c1, c.c2, false, true);
  AddBlock(specs, "block3", c.c2, c.c3, true, true);
  AddBlock(specs, "block4", c.c3, c.c4, true, true);
  const int64_t quarter = c.dim / 4;
  AddConv(specs, "conv1", quarter, c.c1, 1, false);
  AddConv(specs, "conv2", quarter, c.c2, 1, false);
  AddConv(specs, "conv3", quarter, c.c3, 1, false);
  AddConv(specs, "conv4", quarter, c.dim, 1, false);
  AddConv(specs, "score_head.0", 8, c.dim, 1, false);
  AddConv(specs, "score_head.2", 4, 8, 3, false);
  AddConv(specs, "score_head.4", 4, 4, 3, false);
  AddConv(specs, "score_head.6", 1, 4, 3, false);
  const int64_t offsets = 2 * c.num_samples;
  specs.push_back({"desc_head.agg_weights", "float32", {c.num_samples, c.dim, c.dim}});
  AddConv(specs, "desc_head.offset_conv.0", offsets, c.dim, c.kernel, true);
  AddConv(specs, "desc_head.offset_conv.2", offsets, offsets, 1, true);
  AddConv(specs, "desc_head.sf_conv", c.dim, c.dim, 1, false);
  return specs;
}

}  // namespace vmap::neural
