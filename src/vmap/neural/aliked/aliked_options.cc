#include "vmap/neural/aliked/aliked_options.h"

#include <fmt/format.h>

#include "vmap/core/error.h"
#include "vmap/core/option_ranges.h"

namespace vmap {

void AlikedMatcherOptions::Check() const {
  const AlikedMatcherOptions defaults;  // the defaults the messages give, as declared
  if (model != "t16" && model != "n16") {
    throw OptionError("model", "'" + model + "' is not an ALIKED model; use t16 or n16");
  }
  if (device != "cpu" && device != "cuda") {
    throw OptionError("device", "'" + device + "' is not a device; use cpu or cuda");
  }
  if (top_k < 0) {
    throw OptionError("top_k",
                      fmt::format("must be >= 0 (0 = threshold mode with score_threshold; default {})", defaults.top_k),
                      {"score_threshold"});
  }
  if (top_k == 0 && !(score_threshold >= 0.0 && score_threshold < 1.0)) {
    throw OptionError("score_threshold", fmt::format("must be in [0, 1) (0 = the mean score, as upstream; default {})",
                                                     defaults.score_threshold));
  }
  CheckFieldRanges(*this);
}

void AlikedMatcherOptions::VisitFields(OptionFieldVisitor& visitor) {
  visitor.Visit({"model", "--aliked-model", "ALIKED model: t16 or n16"}, model);
  visitor.Visit({"weights", "--weights", "Weights file of the deep matcher (see `vmap weights`)", false, true},
                weights);
  visitor.Visit({"device", "--device", "Deep matchers' device: cpu or cuda"}, device);
  visitor.Visit(OptionField{"top_k", "--aliked-top-k", "ALIKED: keypoints per image (0 = score threshold mode)"}
                    .AtLeast(0)
                    .Meaning("0: score threshold mode"),
                top_k);
  visitor.Visit(
      OptionField{
          "score_threshold", "--aliked-score-threshold",
          "ALIKED: keypoint score threshold when --aliked-top-k is 0 (0, or one no peak passes: the mean score, "
          "as upstream)"}
          .Within(0, 1)
          .ExcludingMax()
          .Meaning("0: the mean score, as upstream"),
      score_threshold);
  visitor.Visit(
      OptionField{"max_keypoints", "--aliked-max-keypoints", "ALIKED: most keypoints when --aliked-top-k is 0"}.AtLeast(
          1),
      max_keypoints);
  visitor.Visit(OptionField{"min_similarity", "--aliked-min-similarity", "ALIKED: least cosine similarity of a match"}
                    .Within(-1, 1)
                    .Meaning("a cosine similarity"),
                min_similarity);
  visitor.Visit(
      OptionField{"longest_side", "--aliked-size", "ALIKED: shrink images to this longest side first (0 = native size)"}
          .AtLeast(32)
          .Or(0)
          .Meaning("0: native size"),
      longest_side);
  visitor.Visit(OptionField{"threads", "--aliked-threads", "ALIKED: LibTorch threads per call (0 = LibTorch default)"}
                    .Within(0, 256)
                    .Meaning("0: LibTorch's default"),
                num_threads);
}

void AlikedMatcherOptions::AfterReading() {
  if (model.rfind("aliked-", 0) == 0) model = model.substr(7);  // maps record the model as aliked-t16
}

}  // namespace vmap
