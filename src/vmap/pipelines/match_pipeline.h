#pragma once
// One image pair through a matcher and the verifier (`vmap match IMAGE0 IMAGE1`, vmap.match, vmap.Matcher):
// the options that set the pair's matching up, and the pipeline that reads two image files, matches them and
// writes the pair's JSON.

#include <memory>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "vmap/core/option_fields.h"
#include "vmap/features/matcher_registry.h"
#include "vmap/geometry/fundamental.h"
#include "vmap/geometry/heading.h"
#include "vmap/mapping/pair_match.h"

namespace vmap {

struct PairMatchOptions {
  HeadingOptions heading;
  MatcherOptions matcher;
  // Verified in full (one pair: no early stop, so no max_samples_to_reject).
  VerifierOptions verifier;

  // The fields above, each once ("heading.min_votes", "matcher", "orb.num_features", "verifier.threshold").
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

struct MatchPipelineOptions {
  std::string image0;  // the first image file
  std::string image1;  // the second
  std::string json;    // every match, the inlier mask, F and the heading; "" = none
  // Intrinsics of both images (fx,fy,cx,cy[,k1,...] or a calibration file): the heading also in degrees; "" = none.
  std::string camera;
  PairMatchOptions pair;

  // The fields above, each once (positional image0 and image1, "json", "camera", then the pair's).
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

struct MatchPipelineResult {
  PairMatch pair;
  cv::Size size0, size1;             // the images' sizes as decoded
  std::string matcher;               // the matcher's name
  std::string matcher_options_json;  // its options, as map.json records them
  double load_seconds = 0.0;         // creating the matcher (a deep model loads its weights)
  bool with_camera = false;          // `camera` given: the heading also in degrees
};

// Matches `image0` against `image1`. Stages, in order:
//   1. check the options and the output (it may overwrite neither image);
//   2. read both images in grey (a FIFO, a device or a size the frame sources refuse is refused before decoding);
//   3. the camera, when given (both images must share a size);
//   4. create the matcher;
//   5. extract, match, verify and estimate the heading (MatchPair), in colour for a matcher that reads colour;
//   6. write the JSON when asked.
// Throws InputError (OptionError for an option) naming what is wrong and how to fix it.
MatchPipelineResult RunMatchPipeline(const MatchPipelineOptions& options);

}  // namespace vmap
