#include "vmap/cli/common_options.h"

namespace vmap::cli {

void AddMatcherOptions(CLI::App* command, MatcherOptions& options) {
  command->add_option("--matcher", options.type, "Feature matcher: orb, loftr, xfeat or aliked")->capture_default_str();
  auto& orb = options.orb;
  command->add_option("--orb-features", orb.num_features, "ORB: features per image")->capture_default_str();
  command->add_option("--orb-scale-factor", orb.scale_factor, "ORB: pyramid scale factor")->capture_default_str();
  command->add_option("--orb-levels", orb.num_levels, "ORB: pyramid levels")->capture_default_str();
  command->add_option("--orb-fast-threshold", orb.fast_threshold, "ORB: FAST threshold")->capture_default_str();
  command->add_option("--orb-edge-threshold", orb.edge_threshold, "ORB: border without features (px)")
      ->capture_default_str();
  command->add_flag("!--no-cross-check", orb.cross_check, "ORB: keep one-way best matches too");
  command->add_option("--ratio", orb.ratio, "ORB: Lowe's ratio test (0 = off), e.g. 0.8")->capture_default_str();
  auto& loftr = options.loftr;
  command->add_option("--loftr-model", loftr.model, "LoFTR preset: outdoor, indoor or coarse")
      ->capture_default_str();
  // --weights and --device belong to whichever deep matcher --matcher picks.
  command->add_option_function<std::string>(
      "--weights",
      [&options](const std::string& file) { options.loftr.weights = options.xfeat.weights = options.aliked.weights = file; },
      "Weights file of the deep matcher (see `vmap weights`)");
  command->add_option_function<std::string>(
      "--device",
      [&options](const std::string& device) {
        options.loftr.device = options.xfeat.device = options.aliked.device = device;
      },
      "Deep matchers' device: cpu or cuda")->default_str(options.loftr.device);
  command->add_option("--loftr-size", loftr.longest_side, "LoFTR: longest image side fed to the network")
      ->capture_default_str();
  command->add_option("--loftr-threshold", loftr.threshold, "LoFTR: coarse confidence threshold (default: preset's)");
  command->add_option("--loftr-threads", loftr.num_threads, "LoFTR: LibTorch threads per call (0 = LibTorch default)")
      ->capture_default_str();
  auto& xfeat = options.xfeat;
  command->add_option("--xfeat-top-k", xfeat.top_k, "XFeat: keypoints kept per image, best first")
      ->capture_default_str();
  command->add_option("--xfeat-threshold", xfeat.detection_threshold, "XFeat: keypoint heatmap threshold")
      ->capture_default_str();
  command->add_option("--xfeat-min-similarity", xfeat.min_similarity,
                      "XFeat: mutual nearest neighbours need a cosine similarity above this (<= 0: no minimum)")
      ->capture_default_str();
  command->add_option("--xfeat-threads", xfeat.num_threads, "XFeat: LibTorch threads per call (0 = LibTorch default)")
      ->capture_default_str();
  auto& aliked = options.aliked;
  command->add_option("--aliked-model", aliked.model, "ALIKED model: t16 or n16")->capture_default_str();
  command->add_option("--aliked-top-k", aliked.top_k, "ALIKED: keypoints per image (0 = score threshold mode)")
      ->capture_default_str();
  command->add_option("--aliked-score-threshold", aliked.score_threshold,
                      "ALIKED: keypoint score threshold when --aliked-top-k is 0")
      ->capture_default_str();
  command->add_option("--aliked-max-keypoints", aliked.max_keypoints,
                      "ALIKED: most keypoints when --aliked-top-k is 0")
      ->capture_default_str();
  command->add_option("--aliked-min-similarity", aliked.min_similarity,
                      "ALIKED: least cosine similarity of a match")
      ->capture_default_str();
  command->add_option("--aliked-size", aliked.longest_side,
                      "ALIKED: shrink images to this longest side first (0 = native size)")
      ->capture_default_str();
  command->add_option("--aliked-threads", aliked.num_threads, "ALIKED: LibTorch threads per call (0 = LibTorch default)")
      ->capture_default_str();
}

VerifierOptions VerifierFlags::Resolve() const {
  VerifierOptions resolved = options;
  resolved.method = ParseVerifierMethod(method);
  resolved.Check();
  return resolved;
}

void AddVerifierOptions(CLI::App* command, VerifierFlags& flags) {
  command->add_option("--verifier", flags.method, "Fundamental matrix estimator: magsac, ransac, usac, accurate")
      ->capture_default_str();
  command->add_option("--threshold", flags.options.threshold, "Verifier inlier threshold in pixels")
      ->capture_default_str();
  command->add_option("--confidence", flags.options.confidence, "Verifier confidence")->capture_default_str();
  command->add_option("--max-iters", flags.options.max_iterations, "Verifier maximum iterations")
      ->capture_default_str();
  command->add_option("--seed", flags.options.seed, "Verifier random seed (same seed, same map)")
      ->capture_default_str();
}

FrameSourceOptions SourceFlags::Resolve() const {
  FrameSourceOptions resolved = options;
  resolved.format = ParseSourceFormat(format);
  resolved.Check();
  return resolved;
}

void AddSourceOptions(CLI::App* command, SourceFlags& flags) {
  command->add_option("--format", flags.format, "Input layout: auto, video, images, tum, euroc, kitti")
      ->capture_default_str();
  command->add_option("--first", flags.options.first, "First frame (0-based)")->capture_default_str();
  command->add_option("--last", flags.options.last, "Last frame, inclusive (-1 = end)")->capture_default_str();
  command->add_option("--stride", flags.options.stride, "Use every N-th frame")->capture_default_str();
  command->add_option("--resize", flags.options.resize, "Resize frames: WxH, or the longest side (e.g. 640)");
  command->add_flag("--strict", flags.options.strict, "Frames of a different size are an error, not a warning");
  command->add_option("--camera", flags.options.camera,
                      "Intrinsics: fx,fy,cx,cy[,k1,k2,p1,p2[,k3]] (pixels, native frame size) or a calibration file "
                      "(OpenCV YAML/JSON, EuRoC sensor.yaml, KITTI calib.txt, intrinsics.txt); 'none' ignores the "
                      "input's own. Default: the input's own, if any");
}

}  // namespace vmap::cli
