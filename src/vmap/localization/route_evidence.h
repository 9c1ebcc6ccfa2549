#pragma once
// What one comparison of a frame with a key image says about whether the frame is there: the log of the ratio of
// its likelihood at a right key image (one bracketing the frame) to its likelihood at a wrong one, the weight
// RouteBelief::Weigh gives it.
//
// It grows with how unlikely the verified matches are by chance (s = -log10 of their number of false alarms,
// acceptance.h) and with their share of the verified matches of the key image's own link in the map (the same
// place, not only the same scene). How much each says depends on the matcher: ORB's chance model separates right
// from wrong key images across lighting (a wrong one rarely reaches s = -1), XFeat's many clustered matches pass
// it at wrong key images too, where the link share and a much higher s tell them apart. So there is one model per
// kind of descriptor, fitted by logistic regression on every frame of corridor_conditions (and michigan_seasons)
// against every key image of their maps (bench/evidence_dump, bench/evidence_fit.py; the fit and the false
// acceptance rates: docs/localize.md, "The belief over the route").

#include "vmap/localization/key_comparison.h"

namespace vmap {

struct EvidenceModel {
  double unmatched = 0.0;         // the log ratio of a comparison without a verified F
  double intercept = 0.0;         // of a matched one: intercept + per_significance * s + per_link_share * share
  double per_significance = 0.0;  // s clamped to [min_significance, max_significance]
  double per_link_share = 0.0;    // share clamped to [0, 1]
  double min_significance = 0.0;
  double max_significance = 0.0;
};

// The fitted models: for binary descriptors (ORB) and for the others (XFeat, ALIKED, LoFTR).
EvidenceModel BinaryDescriptorEvidence();
EvidenceModel FloatDescriptorEvidence();

// `link_verified`: the verified matches of the key image's link with its route neighbour (the smaller of two; 0
// when it has none, and then the share counts as 0).
double EvidenceLogRatio(const EvidenceModel& model, const KeyComparison& comparison, int link_verified);

}  // namespace vmap
