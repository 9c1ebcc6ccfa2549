#pragma once
// A belief over where the frame is along the route: a forward filter (a hidden Markov model) over the route's
// positions, position p being the segment from the route's key image p to key image p + 1 (the last position: at
// the route's last key image). Each frame, the belief is moved by a motion model (a prior on speed: stay, one or
// two key images on, one back, or anywhere), then weighed by the evidence of every key image the frame was
// compared with (RouteEvidence: how much more likely the comparison is at the right place than at a wrong one).
// A frame between key images p and p + 1 sees both, so the evidence of key image q weighs positions q - 1 and q.
//
// Why a forward filter: it keeps what a run of weak comparisons says (each multiplies the belief a little), and a
// single chance match moves only the mass of the positions it is at, against everything the run before it said;
// unlike sequence matching over a window (SeqSLAM) it needs no comparisons of past frames with new key images,
// and unlike a particle filter it is exact and deterministic over a route of a few hundred key images.

#include <vector>

#include "vmap/core/option_fields.h"

namespace vmap {

struct RouteBeliefOptions {
  // The motion model's step (one a frame, or several: motion_steps_per_frame): probabilities of moving by 0, +1, +2 and
  // -1 route positions, and of a jump to any position (the estimate was wrong, the robot was carried). Normalized to
  // sum to 1. The tracker moves by the same steps (LocalizerOptions::lookahead 2, step_back).
  double stay = 0.55;
  double forward = 0.3;
  double forward2 = 0.08;
  double back = 0.05;
  double jump = 0.02;
  // The motion model's steps a frame: a frame that passes more of the route than one step of the model covers is
  // moved by it several times. The probabilities above were fitted where the run passed a key image every third
  // frame (kMotionStepsPerPosition); a run against a map of every place it passes (`vmap build --tau 1` of places,
  // as a park path taught once per place), or one that skips frames (--stride, a lower frame rate, a node that drops
  // frames), passes a key image or more every frame, and a belief that expects one every third frame stays behind
  // its evidence and holds the tracker at a key image the run has left (docs/localize.md, "The motion model's pace").
  // 0: from the map and the run (MotionPace: by time where both have timestamps, else by input index).
  int motion_steps_per_frame = 0;
  // A frame whose belief holds less than this within two positions of its key image is uncertain
  // (LocalizationStatus::kUncertain: not to steer by). 0: never uncertain.
  double min_confidence = 0.5;
  // When the belief doubts the tracked key image (it holds less than min_confidence near it), the frame is also
  // compared with the key images within this many route positions of the belief's peak (behind and ahead), and
  // with the best-ranked ones of the whole route when the belief is flat; the estimate then moves to the belief's
  // peak when the belief singles it out. 0: the belief never moves the estimate (it only flags frames).
  int window = 2;
  // Where the ranking weighs the belief (LocalizerOptions::rank_evidence, XFeat), the estimate moves to the belief's
  // peak only when the belief had singled that place out (within two positions) before the evidence of the frame
  // before this one too: one frame's ranking is not yet a place. Off: one frame (always with ORB).
  bool move_needs_two_frames = true;

  // As a localization run records them ("options.belief"); min_confidence has a flag.
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

class RouteBelief {
 public:
  RouteBelief(int positions, const RouteBeliefOptions& options);

  // Flat: nothing known.
  void Reset();
  // A run that starts at `position`: `mass` there, the rest flat.
  void Start(int position, double mass);
  // One frame of motion: the motion model, `steps` times.
  void Predict(int steps = 1);
  // The evidence of the frame against the route's key image at `position`: the belief at positions `position` - 1
  // and `position` is multiplied by exp(log_ratio). Call Normalize after the frame's last Weigh.
  void Weigh(int position, double log_ratio);
  void Normalize();

  // The belief's mass at positions [position - radius, position + radius].
  double MassWithin(int position, int radius) const;
  // The position of most mass (the first of equals); -1 when empty.
  int Peak() const;
  const std::vector<double>& probabilities() const { return p_; }

 private:
  void PredictOneStep();

  RouteBeliefOptions options_;
  std::vector<double> p_;
  std::vector<double> scratch_;
};

}  // namespace vmap
