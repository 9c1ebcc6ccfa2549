// The Localizer's belief over the route (route_belief.h): every comparison of a frame weighs it; a frame whose
// tracked position the belief does not single out is questioned (compared around the belief's peak, and over the
// whole route when the belief is flat), moved to where the belief puts it, or else uncertain.
#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "vmap/localization/localizer.h"

namespace vmap {

namespace {

// The positions a result records its belief at (LocalizationResult::belief): those holding at least this.
constexpr double kRecordedMass = 0.01;

}  // namespace

void Localizer::WeighComparisons() {
  bool weighed = RankingMovesOwnFrame() && WeighRanking();
  for (Memo& m : comparisons_) {
    if (m.weighed && (!m.by_heading || m.weighed_by_heading)) continue;
    // A blind frame verifies nothing anywhere, which says nothing of where it is: calibrated on frames that could
    // verify, nothing verified weighs against the key image, and two black frames took the belief from the tracked
    // key image (confidence 0.95 to 0.25) and the next real frame was withheld.
    if (blind_) {
      m.weighed = true;
      m.weighed_by_heading = m.by_heading;
      continue;
    }
    const int key = m.comparison.key;
    const int position = route_position_of_key_[key];
    if (position < 0) {
      m.weighed = true;
      continue;
    }
    double log_ratio = 0.0;
    if (!m.weighed) {
      m.weighed_ranked = !bucket_of_position_.empty();
      const int bucket = m.weighed_ranked ? bucket_of_position_[position] : -1;
      log_ratio = EvidenceLogRatio(evidence_, m.comparison, link_verified_[key], bucket);
      if (m.by_heading) log_ratio = std::max(log_ratio, evidence_.heading_stands_out);
    } else {
      // Weighed before the heading accepted it: what the acceptance adds.
      const int bucket = m.weighed_ranked ? bucket_of_position_[position] : -1;
      log_ratio = std::max(
          0.0, evidence_.heading_stands_out - EvidenceLogRatio(evidence_, m.comparison, link_verified_[key], bucket));
    }
    m.weighed = weighed = true;
    m.weighed_by_heading = m.by_heading;
    WeighBeliefs(position, log_ratio);
  }
  if (weighed) NormalizeBeliefs();
}

void Localizer::WeighBeliefs(int position, double log_ratio) {
  belief_.Weigh(position, log_ratio);
  if (start_unconfirmed_) evidence_belief_.Weigh(position, log_ratio);
}

void Localizer::NormalizeBeliefs() {
  belief_.Normalize();
  if (start_unconfirmed_) evidence_belief_.Normalize();
}

bool Localizer::WeighRanking() {
  if (blind_ || ranked_.empty() || !bucket_of_position_.empty() || evidence_.rank_alone.empty()) return false;
  // The ranking holds the route's key images in route order: ranked_[r].key is a route position.
  bucket_of_position_ = RankingBuckets(evidence_, ranked_, static_cast<int>(route_.size()));
  for (size_t p = 0; p < route_.size(); ++p)
    WeighBeliefs(static_cast<int>(p), RankLogRatio(evidence_, bucket_of_position_[p]));
  // A comparison weighed before the frame was ranked said what its rank now says in part: it weighs what it adds to
  // the rank instead.
  for (Memo& m : comparisons_) {
    if (!m.weighed || m.weighed_ranked) continue;
    m.weighed_ranked = true;
    const int key = m.comparison.key;
    const int position = route_position_of_key_[key];
    if (position < 0) continue;
    WeighBeliefs(position,
                 EvidenceLogRatio(evidence_, m.comparison, link_verified_[key], bucket_of_position_[position]) -
                     EvidenceLogRatio(evidence_, m.comparison, link_verified_[key]));
  }
  return true;
}

bool Localizer::SinglesOut(const RouteBelief& belief, int position) const {
  // Near the position: at least min_confidence of the belief, and twice what a flat belief holds there (on a
  // short route a flat belief holds much of its mass within two places of anywhere).
  const double near = belief.MassWithin(position, kNear);
  const int positions = static_cast<int>(belief.probabilities().size());
  const double flat = static_cast<double>(std::min(positions, 2 * kNear + 1)) / positions;
  return near >= options_.belief.min_confidence && near >= 2.0 * flat;
}

bool Localizer::EvidencePointsAway(int position) const {
  if (!start_unconfirmed_ || options_.belief.min_confidence <= 0.0) return false;
  const int peak = evidence_belief_.Peak();
  return std::abs(peak - position) > kNear && SinglesOut(evidence_belief_, peak) &&
         evidence_belief_.MassWithin(position, kNear) < options_.belief.min_confidence;
}

bool Localizer::EvidenceWeighsAgainst(int position) const {
  if (!start_unconfirmed_ || !options_.start_needs_evidence || options_.belief.min_confidence <= 0.0) return false;
  // A flat belief holds `flat` there: below it, the frames' comparisons moved mass away from the place. Where the place
  // and its neighbours hold more than half the route (michigan_seasons' routes of 5 places), near and elsewhere are not
  // told apart, as a place cannot be singled out there (SinglesOut: twice a flat belief).
  const double flat = static_cast<double>(NearWidth(position)) / route_.size();
  return TellsNearFromFar(position) && evidence_belief_.MassWithin(position, kNear) < flat;
}

void Localizer::Believe(LocalizationResult& result, const Frame& frame, const ImageFeatures& features) {
  const bool placed_by_tracker = IsPlaced(result.status);
  WeighComparisons();
  SettleStepOn(result, features);
  SettleStepBack(result, features);
  StepOnByBelief(result, features);
  Question(result, frame, features);
  DoubtJumpBack(result);
  // Not to steer by at route `position`: the belief holds less than min_confidence near it, or the frames' evidence
  // alone points away from it or weighs against it while the start is unconfirmed.
  auto withholds = [&](int position) {
    return belief_.MassWithin(position, kNear) < options_.belief.min_confidence || EvidencePointsAway(position) ||
           EvidenceWeighsAgainst(position);
  };
  // ORB's ranking of the frame weighs the belief only now (EvidenceModel::ranking_moves_own_frame off): the rules above
  // moved the tracker on the frame's comparisons and the frames before it, and the frame's own ranking may withhold
  // the frame (judged with it and without it), never move it or steer by it; the frames after it are weighed by it as
  // by any evidence.
  const int position = result.route_position;
  const bool withheld_unranked = position >= 0 && withholds(position);
  const int evidence_peak_unranked = evidence_belief_.Peak();
  const bool ranked_now = !RankingMovesOwnFrame() && WeighRanking();
  if (ranked_now) NormalizeBeliefs();
  const std::vector<double>& p = belief_.probabilities();
  for (size_t i = 0; i < p.size() && i < route_.size(); ++i) {
    if (p[i] >= kRecordedMass) result.belief.emplace_back(route_[i], std::round(1000.0 * p[i]) / 1000.0);
  }
  if (position < 0) return;
  result.confidence = belief_.MassWithin(position, kNear);
  const bool placed = IsPlaced(result.status);
  // Ranked first: the ranking may weigh the frames' evidence alone (start_evidence_ranks_frame), which `withholds` then
  // reads.
  const auto start_ranking = placed ? RankForUnconfirmedStart(result, frame, features) : std::nullopt;
  const bool ties_far = start_ranking && StartPlaceTiesFar(result, features, *start_ranking);
  if (placed) {
    // The first rule that withholds the frame names it.
    Withholding rule = Withholding::kNone;
    if (ties_far) {
      rule = Withholding::kStartUnconfirmed;
    } else if (withheld_unranked || withholds(position)) {
      rule = Withholding::kBelief;
    } else if (PlacedAwayOnLittleChance(result)) {
      rule = Withholding::kLittleChance;
    } else if (StartAwayLacksBelief(result)) {
      rule = Withholding::kStartUnconfirmed;
    }
    if (rule != Withholding::kNone) {
      result.status = LocalizationStatus::kUncertain;
      result.withheld_by = rule;
    }
  }
  // Confirmed: the frames' evidence alone leans most near the place the frame is steered by (with the frame's ranking
  // and without it).
  if (start_unconfirmed_ && placed && result.status != LocalizationStatus::kUncertain &&
      std::abs(evidence_belief_.Peak() - position) <= kNear && std::abs(evidence_peak_unranked - position) <= kNear) {
    start_unconfirmed_ = false;
  }
  // An uncertain frame's key images are the best guess: the belief's peak when the belief singles it out and holds
  // more there than near the tracker's key image (the tracker goes on from its own, but from a jump the belief
  // withholds; nothing steers by this frame). A flat belief's peak is no better a guess than the tracker's
  // (corridor_conditions, docs/localize.md).
  const int peak = belief_.Peak();
  if (options_.belief.window > 0 && result.status == LocalizationStatus::kUncertain && peak != result.route_position &&
      belief_confident_ && SinglesOut(peak) && belief_.MassWithin(peak, kNear) > result.confidence) {
    LocalizationResult guess;
    guess.candidates = std::move(result.candidates);
    Describe(guess, peak, features);
    guess.status = LocalizationStatus::kUncertain;
    guess.withheld_by = result.withheld_by;
    guess.belief = std::move(result.belief);
    guess.confidence = belief_.MassWithin(peak, kNear);
    result = std::move(guess);
    // The tracker jumped on this frame, and the belief withholds the place it jumped to and guesses one nearer where
    // the run was last steered by: the jump is not taken (jump_needs_belief).
    if (options_.jump_needs_belief && frame_start_position_ >= 0 && position_ >= 0 && steered_before_ >= 0 &&
        std::abs(position_ - frame_start_position_) > kNear && std::abs(position_ - peak) > kNear &&
        std::abs(peak - steered_before_) < std::abs(position_ - steered_before_)) {
      position_ = peak;
      step_back_ruled_out_ = {};
    }
  }
  // Doubted only by the belief before the frame's own ranking (the tracker placed the frame, and the rules above
  // withhold nothing with the ranking): the frame's comparison at its key images passes chance where the belief with
  // its ranking singles the place out and the tracker is. Chance, the ranking and the tracker agree; the mass before
  // the ranking is the frames before's, left where they were.
  if (ranked_now && options_.verified_ranking_steers && placed_by_tracker &&
      result.status == LocalizationStatus::kUncertain && position_ >= 0 &&
      std::abs(position_ - result.route_position) <= kNear && std::abs(peak - result.route_position) <= kNear &&
      (PassesChance(result.to_key, options_.max_log10_nfa) || PassesChance(result.to_next, options_.max_log10_nfa)) &&
      SinglesOut(result.route_position) && !withholds(result.route_position)) {
    result.status = LocalizationStatus::kRelocalized;
  }
  // A far place refused on one frame (TakesJump: pointed_) that the belief, with the frame's evidence, does not follow:
  // the frame is steered by where the belief singles out a place within kNear of the tracker, not behind the place the
  // run was last steered by, and a comparison there verifies beyond a little chance, the link share aside, while no
  // accepted far comparison stands out against it by min_rival_ratio (steer_where_belief_stays).
  if (options_.steer_where_belief_stays && pointed_ >= 0 && result.status == LocalizationStatus::kUncertain &&
      position_ >= 0 && std::abs(position_ - result.route_position) <= kNear &&
      (steered_before_ < 0 || result.route_position >= steered_before_) &&
      std::abs(peak - result.route_position) <= kNear && SinglesOut(result.route_position) &&
      !withholds(result.route_position)) {
    int near_verified = 0;  // of the comparisons at the place beyond a little chance
    for (const KeyComparison* c : {&result.to_key, &result.to_next}) {
      if (c->matched && c->log10_nfa <= kBeyondLittleChance) near_verified = std::max(near_verified, c->num_verified);
    }
    if (near_verified > 0 &&
        !StandsOut(MostVerifiedAway(result.route_position, /*accepted_only=*/true), near_verified)) {
      result.status = LocalizationStatus::kTracking;
    }
  }
  WeighStartQuestion();  // the frames after this one carry it
}

void Localizer::MoveTrackerTo(LocalizationResult& result, int position, LocalizationStatus status,
                              const ImageFeatures& features) {
  LocalizationResult moved;
  moved.candidates = std::move(result.candidates);
  Describe(moved, position, features);
  moved.status = status;
  result = std::move(moved);
  position_ = position;
  step_back_ruled_out_ = {};
}

void Localizer::SettleStepOn(LocalizationResult& result, const ImageFeatures& features) {
  const int reached = result.route_position;
  if (steps_on_ <= 0 || options_.belief.window <= 0 || result.status != LocalizationStatus::kTracking || reached < 2) {
    return;
  }
  const std::vector<double>& p = belief_.probabilities();
  const int passed = reached - 1;
  // Two key images on: back when the belief holds more on the segment after the passed key image than after the
  // reached one (one key image a frame is likelier than two). One key image on: back when the belief holds more on
  // the segment before the key image left than after the one reached, and more there than a flat belief would (where
  // it holds next to nothing on either side, it is sure of the segment between them and cannot tell which is nearer).
  const bool back = steps_on_ >= 2
                        ? p[passed] > p[reached]
                        : p[reached - 2] > p[reached] && p[reached - 2] > 1.0 / static_cast<double>(p.size());
  // The key image passed need not verify (hold_unearned_step_on) where the map joins it to the one reached by a link of
  // one scene: that one, now `next_key`, verifies, and the frame is on the segment between them (not between two
  // unrelated places: a --tau 1 map's).
  const bool hold = options_.hold_unearned_step_on && scene_link_after_[passed];
  if (!back || (!hold && !comparisons_.Once(features, route_[passed]).accepted)) return;
  MoveTrackerTo(result, passed, LocalizationStatus::kTracking, features);
}

void Localizer::SettleStepBack(LocalizationResult& result, const ImageFeatures& features) {
  const int left = stepped_back_from_;
  const int reached = result.route_position;
  if (!options_.step_back_needs_belief || left < 0 || options_.belief.window <= 0 || !IsPlaced(result.status) ||
      reached >= left || left - reached > kNear) {
    return;
  }
  // Beyond the evidence's bound the key image reached is the same scene beyond doubt (the same season: redkitchen's
  // hand-held camera reverses, verifying at log10 NFA -200 to -460), and the counts decide, as NoLikelierChance has it.
  if (result.to_key.accepted && result.to_key.log10_nfa <= -evidence_.max_significance) return;
  // Segment `left` is past the key image left, segment reached - 1 before the key image reached; the segments between
  // are the frame's either way (two key images a frame apart that look alike are not told apart by one frame).
  const std::vector<double>& p = belief_.probabilities();
  const double before_reached = reached > 0 ? p[reached - 1] : 0.0;
  // Only where the belief holds the frame near the key image left as it would to steer by it (min_confidence): a
  // step back is not traded for an uncertain frame.
  const bool undo = p[left] > before_reached && p[left] > 1.0 / static_cast<double>(p.size()) &&
                    belief_.MassWithin(left, kNear) >= options_.belief.min_confidence;
  if (!undo || !comparisons_.Once(features, route_[left]).accepted) return;
  MoveTrackerTo(result, left, LocalizationStatus::kTracking, features);
}

void Localizer::StepOnByBelief(LocalizationResult& result, const ImageFeatures& features) {
  // A flat belief (the frames before this one singled out no place) does not move the tracker: one frame's evidence
  // leans anywhere (a run's first frame). Only where the frame's ranking weighs the belief before its moves (XFeat)
  // does the belief know more than the counts the tracker stepped by; ORB's frame is weighed by those comparisons alone
  // until its moves are made (with it, before ORB's ranking was weighed, redkitchen's teach/repeat run lost 2 frames
  // steered by at a right key image; a step on by the belief added back-jumps with ORB's ranking weighed).
  if (!options_.step_on_by_belief || !RankingMovesOwnFrame() || options_.belief.window <= 0 || !belief_confident_ ||
      !IsPlaced(result.status) || result.route_position < 0) {
    return;
  }
  const std::vector<double>& p = belief_.probabilities();
  const int last = static_cast<int>(route_.size()) - 1;
  const int from = result.route_position;
  auto mass = [&](int first, int end) {  // positions [first, end)
    double sum = 0.0;
    for (int i = std::max(0, first); i < std::min(end, last + 1); ++i) sum += p[i];
    return sum;
  };
  int to = from;
  for (int q = from; q < last && q + 1 - from <= lookahead_; ++q) {
    // At key image q the frame is on segment q - 1 or q; past key image q + 1, on q + 1 or after (the belief's mass on
    // as many positions each side: LocalizerOptions::step_on_by_belief_ahead).
    if (mass(q + 1, q + 1 + options_.step_on_by_belief_ahead) <= mass(q - 1, q + 1)) break;
    if (!comparisons_.Once(features, route_[q + 1]).accepted) break;
    to = q + 1;
  }
  if (to == from) return;
  MoveTrackerTo(result, to, result.status, features);
}

void Localizer::Question(LocalizationResult& result, const Frame& frame, const ImageFeatures& features) {
  const int window = options_.belief.window;
  const double min_confidence = options_.belief.min_confidence;
  const int last = static_cast<int>(route_.size()) - 1;
  auto doubted = [&] {
    return result.status == LocalizationStatus::kLost || result.route_position < 0 ||
           belief_.MassWithin(result.route_position, kNear) < min_confidence;
  };
  if (window <= 0 || min_confidence <= 0.0 || !doubted()) return;
  // A blind frame is no evidence that the estimate is wrong: moved to the belief's peak, which trails the tracker, it
  // put the tracker back a key image.
  if (blind_) return;
  // The key image stops explaining the frame: look where the belief has it, behind and ahead of its peak (the key
  // images whose evidence weighs the positions within `window` of it).
  auto compare_around = [&](int centre) {
    std::vector<int> meanwhile;  // the first is compared at once; the helper starts from the last
    for (int q = std::min(last, centre + window + 1); q > std::max(0, centre - window); --q) meanwhile.push_back(q);
    CompareMeanwhile(features, meanwhile);
    for (int q = std::max(0, centre - window); q <= std::min(last, centre + window + 1); ++q) {
      comparisons_.Once(features, route_[q]);
    }
    WeighComparisons();
  };
  compare_around(belief_.Peak());
  if (!belief_confident_) {
    // Flat: nothing singled out. The best-ranked key images of the whole route weigh it (a relocalization). A
    // flat belief does not move the estimate on one frame's evidence: the frames after it confirm a place.
    CompareBestRanked(frame, features);
    WeighComparisons();
    return;
  }
  const int peak = belief_.Peak();
  if (!doubted() || !SinglesOut(peak)) return;
  // Where the ranking weighs the belief (XFeat), one frame's ranking can single out a place: a key image where the
  // corridor repeats itself ranks first on a dark frame. One frame's evidence is not yet a place: the belief moves the
  // estimate only where it had singled out the place before the evidence of the frame before this one too. (ORB's
  // belief, weighed by its comparisons alone, moves on one frame: two cost corridor_conditions' runs frames.)
  if (options_.belief.move_needs_two_frames && RankingMovesOwnFrame() &&
      (confident_peak_before_ < 0 || std::abs(confident_peak_before_ - peak) > kNear)) {
    return;
  }
  // A frame the tracker relocalized elsewhere on a verified key image: one frame does not undo the run before it
  // (a chance match looks alike), but the robot may have been carried. The tracker goes on from the new place, so
  // that the frames after it confirm or refute it; the frame is uncertain, its best guess the belief's peak.
  const bool jumped = result.status == LocalizationStatus::kRelocalized;
  // The run of frames before this one singled out a place, and this frame's evidence leaves it there: the
  // estimate moves there. It is relocalized when a key image there verifies; on weak evidence alone (nothing
  // verifies) its key images are the best guess, not to steer by.
  LocalizationResult moved;
  moved.candidates = std::move(result.candidates);
  Describe(moved, peak, features);
  const bool verified = moved.to_key.accepted || moved.to_next.accepted;
  moved.status = verified && !jumped ? LocalizationStatus::kRelocalized : LocalizationStatus::kUncertain;
  // A frame already withheld keeps the rule that withheld it: the move only gives its best guess.
  if (jumped) {
    moved.withheld_by = Withholding::kFarPlaceOnOneFrame;
  } else if (!verified) {
    moved.withheld_by = result.withheld_by != Withholding::kNone ? result.withheld_by : Withholding::kBeliefMoved;
  }
  result = std::move(moved);
  if (jumped) return;
  position_ = peak;
  step_back_ruled_out_ = {};
  if (verified) lost_in_a_row_ = 0;
}

double Localizer::NearDensity(int position) const { return belief_.MassWithin(position, kNear) / NearWidth(position); }

bool Localizer::TellsNearFromFar(int position) const {
  return 2 * NearWidth(position) <= static_cast<int>(route_.size());
}

int Localizer::NearWidth(int position) const {
  const int last = static_cast<int>(route_.size()) - 1;
  return std::min(last, position + kNear) - std::max(0, position - kNear) + 1;
}

}  // namespace vmap
