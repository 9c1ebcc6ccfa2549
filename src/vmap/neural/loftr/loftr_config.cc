#include "vmap/neural/loftr/loftr_config.h"

#include "vmap/core/error.h"

namespace vmap::neural {

namespace {

void AddBatchNorm(std::vector<TensorSpec>& specs, const std::string& prefix, int64_t channels) {
  for (const char* name : {"weight", "bias", "running_mean", "running_var"}) {
    specs.push_back({prefix + "." + name, "float32", {channels}});
  }
  specs.push_back({prefix + ".num_batches_tracked", "int64", {}});
}

void AddConv(std::vector<TensorSpec>& specs, const std::string& key, int64_t out, int64_t in, int64_t k) {
  specs.push_back({key, "float32", {out, in, k, k}});
}

// Two residual blocks; the first changes width and (for stride 2) resolution, so it owns the projection.
void AddResidualStage(std::vector<TensorSpec>& specs, const std::string& prefix, int64_t in, int64_t out,
                      bool strided) {
  for (int block = 0; block < 2; ++block) {
    const std::string p = prefix + "." + std::to_string(block);
    const int64_t block_in = block == 0 ? in : out;
    AddConv(specs, p + ".conv1.weight", out, block_in, 3);
    AddConv(specs, p + ".conv2.weight", out, out, 3);
    AddBatchNorm(specs, p + ".bn1", out);
    AddBatchNorm(specs, p + ".bn2", out);
    if (block == 0 && strided) {
      AddConv(specs, p + ".downsample.0.weight", out, block_in, 1);
      AddBatchNorm(specs, p + ".downsample.1", out);
    }
  }
}

// One top-down FPN merge: 1x1 lateral conv to the wider width, then conv-BN-LeakyReLU-conv to the narrower.
void AddFpnMerge(std::vector<TensorSpec>& specs, const std::string& level, int64_t lateral_in, int64_t wide,
                 int64_t narrow) {
  AddConv(specs, "backbone." + level + "_outconv.weight", wide, lateral_in, 1);
  AddConv(specs, "backbone." + level + "_outconv2.0.weight", wide, wide, 3);
  AddBatchNorm(specs, "backbone." + level + "_outconv2.1", wide);
  AddConv(specs, "backbone." + level + "_outconv2.3.weight", narrow, wide, 3);
}

void AddTransformer(std::vector<TensorSpec>& specs, const std::string& prefix, int num_layers, int64_t d) {
  for (int i = 0; i < num_layers; ++i) {
    const std::string p = prefix + ".layers." + std::to_string(i);
    for (const char* proj : {"q_proj", "k_proj", "v_proj", "merge"}) {
      specs.push_back({p + "." + proj + ".weight", "float32", {d, d}});
    }
    specs.push_back({p + ".mlp.0.weight", "float32", {2 * d, 2 * d}});
    specs.push_back({p + ".mlp.2.weight", "float32", {d, 2 * d}});
    for (const char* norm : {"norm1", "norm2"}) {
      specs.push_back({p + "." + norm + ".weight", "float32", {d}});
      specs.push_back({p + "." + norm + ".bias", "float32", {d}});
    }
  }
}

}  // namespace

const std::vector<std::string>& LoftrPresetNames() {
  static const std::vector<std::string> names{"outdoor", "indoor", "coarse"};
  return names;
}

LoftrConfig LoftrPreset(const std::string& name) {
  LoftrConfig config;  // the defaults are outdoor_ds
  config.preset = name;
  if (name == "outdoor") return config;
  if (name == "indoor") {
    config.temp_bug_fix = true;
    config.border_removal = 0;
    return config;
  }
  if (name == "coarse") {
    config.backbone = BackboneKind::kResNetFpn16_4;
    config.initial_dim = 8;
    config.block_dims = {8, 16, 32, 32};
    config.coarse_stride = 16;
    config.d_model = 32;
    config.nhead = 1;
    config.num_coarse_layer_pairs = 2;
    config.layer_norm_eps = 1e-7;
    config.temp_bug_fix = false;
    config.border_removal = 2;
    config.has_fine = false;
    return config;
  }
  throw InputError("unknown LoFTR model '" + name + "'; use outdoor, indoor or coarse");
}

std::vector<TensorSpec> ExpectedStateDict(const LoftrConfig& config) {
  std::vector<TensorSpec> specs;
  const auto& dims = config.block_dims;
  AddConv(specs, "backbone.conv1.weight", config.initial_dim, 1, 7);
  AddBatchNorm(specs, "backbone.bn1", config.initial_dim);
  int64_t in = config.initial_dim;
  for (size_t stage = 0; stage < dims.size(); ++stage) {
    AddResidualStage(specs, "backbone.layer" + std::to_string(stage + 1), in, dims[stage], stage > 0);
    in = dims[stage];
  }
  // Top-down path, deepest level first, as the modules are registered upstream.
  const int deepest = static_cast<int>(dims.size());
  const int finest = config.backbone == BackboneKind::kResNetFpn8_2 ? 1 : 2;
  AddConv(specs, "backbone.layer" + std::to_string(deepest) + "_outconv.weight", dims[deepest - 1], dims[deepest - 1],
          1);
  for (int level = deepest - 1; level >= finest; --level) {
    AddFpnMerge(specs, "layer" + std::to_string(level), dims[level - 1], dims[level], dims[level - 1]);
  }
  AddTransformer(specs, "loftr_coarse", 2 * config.num_coarse_layer_pairs, config.d_model);
  if (config.has_fine) {
    const int64_t fine = config.fine_d_model;
    if (config.fine_concat_coarse_feat) {
      specs.push_back({"fine_preprocess.down_proj.weight", "float32", {fine, config.d_model}});
      specs.push_back({"fine_preprocess.down_proj.bias", "float32", {fine}});
      specs.push_back({"fine_preprocess.merge_feat.weight", "float32", {fine, 2 * fine}});
      specs.push_back({"fine_preprocess.merge_feat.bias", "float32", {fine}});
    }
    AddTransformer(specs, "loftr_fine", 2 * config.num_fine_layer_pairs, fine);
  }
  return specs;
}

}  // namespace vmap::neural
