#include "vmap/neural/xfeat/xfeat_options.h"

#include "vmap/core/error.h"
#include "vmap/core/option_ranges.h"

namespace vmap {

void XfeatMatcherOptions::Check() const {
  if (device != "cpu" && device != "cuda") {
    throw OptionError("device", "'" + device + "' is not a device; use cpu or cuda");
  }
  CheckFieldRanges(*this);
}

void XfeatMatcherOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit({"weights", "--weights", "Weights file of the deep matcher (see `vmap weights`)", false, true},
                weights);
  visitor.Visit({"device", "--device", "Deep matchers' device: cpu or cuda"}, device);
  visitor.Visit(OptionField{"top_k", "--xfeat-top-k", "XFeat: keypoints kept per image, best first"}.AtLeast(1), top_k);
  visitor.Visit(OptionField{"detection_threshold", "--xfeat-threshold", "XFeat: keypoint heatmap threshold"}
                    .Within(0, 1)
                    .ExcludingMax()
                    .Meaning("a heatmap value; upstream 0.05"),
                detection_threshold);
  visitor.Visit(OptionField{"min_similarity", "--xfeat-min-similarity",
                            "XFeat: mutual nearest neighbours need a cosine similarity above this (<= 0: no minimum)"}
                    .Within(-1, 1)
                    .ExcludingMax()
                    .Meaning("a cosine similarity; upstream 0.82, -1 keeps every mutual nearest neighbour"),
                min_similarity);
  visitor.Visit(OptionField{"threads", "--xfeat-threads", "XFeat: LibTorch threads per call (0 = LibTorch default)"}
                    .Within(0, 256)
                    .Meaning("0: LibTorch's default"),
                num_threads);
}

}  // namespace vmap
