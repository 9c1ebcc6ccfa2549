#include "vmap/neural/xfeat/xfeat_options.h"

#include "vmap/core/error.h"

namespace vmap {

void XfeatMatcherOptions::Check() const {
  if (device != "cpu" && device != "cuda") {
    throw OptionError("device", "'" + device + "' is not a device; use cpu or cuda");
  }
  if (top_k < 1) {
    throw OptionError("top_k", std::to_string(top_k) + " must be at least 1 (upstream default 4096)");
  }
  if (!(detection_threshold >= 0.0 && detection_threshold < 1.0)) {
    throw OptionError("detection_threshold", "must be in [0, 1) (a heatmap value; upstream 0.05)");
  }
  if (!(min_similarity >= -1.0 && min_similarity < 1.0)) {
    throw OptionError("min_similarity",
                      "must be in [-1, 1) (a cosine similarity; upstream 0.82, -1 keeps every "
                      "mutual nearest neighbour)");
  }
  if (num_threads < 0) throw OptionError("threads", "must be >= 0 (0 = LibTorch's default)");
}

void XfeatMatcherOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit({"weights", "--weights", "Weights file of the deep matcher (see `vmap weights`)", false, true},
                weights);
  visitor.Visit({"device", "--device", "Deep matchers' device: cpu or cuda"}, device);
  visitor.Visit({"top_k", "--xfeat-top-k", "XFeat: keypoints kept per image, best first"}, top_k);
  visitor.Visit({"detection_threshold", "--xfeat-threshold", "XFeat: keypoint heatmap threshold"}, detection_threshold);
  visitor.Visit({"min_similarity", "--xfeat-min-similarity",
                 "XFeat: mutual nearest neighbours need a cosine similarity above this (<= 0: no minimum)"},
                min_similarity);
  visitor.Visit({"threads", "--xfeat-threads", "XFeat: LibTorch threads per call (0 = LibTorch default)"}, num_threads);
}

}  // namespace vmap
