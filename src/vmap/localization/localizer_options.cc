#include "vmap/localization/localizer_options.h"

#include "vmap/core/error.h"
#include "vmap/core/option_ranges.h"

namespace vmap {
namespace {

constexpr char kRulesSection[] =
    "Rules across seasons and lighting (each on by default and measured: docs/localize.md; a flag turns one off to "
    "measure it)";

}  // namespace

void LocalizerOptions::VisitFields(OptionFieldVisitor& visitor) {
  // The sections --help lists the flags under, the everyday ones first; the rules each have a flag to turn them off
  // for a measurement, not to tune.
  visitor.Section("Start: where on the route the run begins");
  visitor.Visit(
      OptionField{"start_key", "--start-key",
                  "The key image the run starts at (teach and repeat: 0, the route's first): the tracker starts there "
                  "and the belief leans there, which the frames' evidence overrides (-1 = anywhere)"}
          .AtLeast(-1)
          .Meaning("-1: anywhere"),
      start_key);
  visitor.Visit(
      OptionField{"start_mass", "--start-mass",
                  "--start-key: the share of the belief at the start key image at the first frame (the rest flat)"}
          .Within(0, 1)
          .ExcludingMax()
          .Meaning("1 would trap a run started elsewhere"),
      start_mass);
  visitor.Visit({"start_is_hint", "!--no-start-is-hint",
                 "--start-key: steer by a frame even where the frames' evidence alone, without the start's prior, "
                 "singles out a place more than two key images away (otherwise it is uncertain)"},
                start_is_hint);
  visitor.Visit({"start_needs_evidence", "!--no-start-needs-evidence",
                 "--start-key: steer by a frame before the start is confirmed even where the frames' evidence alone "
                 "holds less near its key image than a flat belief would (otherwise it is uncertain)"},
                start_needs_evidence);
  visitor.Visit({"start_place_stands_out", "!--no-start-place-stands-out",
                 "--start-key, float descriptors: steer by a frame before the start is confirmed even where a key "
                 "image more than two places away verifies as much (otherwise it is uncertain)"},
                start_place_stands_out);
  visitor.Visit({"start_question_weighs", "!--no-start-question-weighs",
                 "--start-key, float descriptors: the far key image compared to ask whether the start's place stands "
                 "out is not weighed into the belief (otherwise it weighs it once the frame is decided)"},
                start_question_weighs);
  visitor.Visit({"start_evidence_ranks_frame", "!--no-start-evidence-ranks-frame",
                 "--start-key, float descriptors: before the start is confirmed, the frames' evidence alone weighs a "
                 "tracked frame by its comparisons only (otherwise by its ranking too)"},
                start_evidence_ranks_frame);
  visitor.Visit(
      OptionField{"start_away_min_confidence", "--start-away-min-confidence",
                  "--start-key, float descriptors: before the start is confirmed, the belief a frame placed more than "
                  "two key images from the start key image needs near its place to be steered by (0: as any frame)"}
          .Within(0, 1),
      start_away_min_confidence);
  visitor.Section("Acceptance: when a frame is at a key image");
  visitor.Visit({"acceptance", "--acceptance",
                 "When a frame is seen at a key image: chance (its verified matches are unlikely by "
                 "chance, --max-log10-nfa, and many against the map's links, --min-link-share) or "
                 "counts (the earlier rule: --min-verified and --min-similarity)"},
                EnumField(acceptance, kAcceptanceRuleNames, ParseAcceptanceRule));
  visitor.Visit(OptionField{"max_log10_nfa", "--max-log10-nfa",
                            "--acceptance chance: accept when log10 of the number of false alarms is at most this"}
                    .Within(-1000, 1000)
                    .Meaning("0: accept what chance explains less than once"),
                max_log10_nfa);
  visitor.Visit(OptionField{"min_verified", "--min-verified",
                            "--acceptance counts: verified matches a frame needs to be localized at a key image"}
                    .Within(8, 100000)
                    .Meaning("8: the fewest matches F can be verified with"),
                min_verified);
  visitor.Visit(OptionField{"min_similarity", "--min-similarity",
                            "--acceptance counts: S a frame needs to be localized at a key image"}
                    .Within(0, 1),
                min_similarity);
  visitor.Visit(
      OptionField{"min_link_share", "--min-link-share",
                  "--acceptance chance: verified matches a frame also needs, as a fraction of those of the key "
                  "image's link with its route neighbour (0: chance alone)"}
          .Within(0, 10)
          .Meaning("0: chance alone decides"),
      min_link_share);
  visitor.Visit(
      OptionField{"link_share_tau", "--link-share-tau",
                  "--acceptance chance: on a map built with a higher tau (--tau 1: every frame a key image), "
                  "--min-link-share measures against a key image's link as a map of this tau would hold it (0: the "
                  "matcher's default tau; 1: the map's own links)"}
          .Within(0, 1)
          .Meaning("0: the map's matcher's default tau"),
      link_share_tau);
  visitor.Visit(
      OptionField{"min_rival_ratio", "--min-rival-ratio",
                  "--acceptance chance: a key image refused by --min-link-share alone is accepted when it verifies "
                  "this many times the matches of every key image compared more than two route positions away (the "
                  "tracked ones each, else the best of a relocalization's; 0: never)"}
          .Within(1, 1000)
          .Or(0)
          .Meaning("0: never"),
      min_rival_ratio);
  visitor.Visit(
      OptionField{"rival_max_log10_nfa", "--rival-max-log10-nfa",
                  "--acceptance chance: the log10 number of false alarms a key image accepted against its rivals "
                  "(--min-rival-ratio) needs at most"}
          .Within(-1000, 0),
      rival_max_log10_nfa);
  visitor.Visit(
      OptionField{"min_heading_rival_ratio", "--min-heading-rival-ratio",
                  "--acceptance chance, binary descriptors: a key image chance refuses is accepted when its heading "
                  "mode holds this many times the votes of every rival compared (far, or near without a link of one "
                  "scene; 0: never)"}
          .Within(1, 1000)
          .Or(0)
          .Meaning("0: never"),
      min_heading_rival_ratio);
  visitor.Visit(
      OptionField{"min_heading_votes", "--min-heading-votes",
                  "The matches a heading mode needs to be accepted against its rivals (--min-heading-rival-ratio)"}
          .Within(3, 100000),
      min_heading_votes);
  visitor.Section("Tracking and relocalization");
  visitor.Visit(
      OptionField{"max_lost_frames", "--max-lost", "Lost frames in a row before the estimate is dropped"}.Within(
          0, 1000000),
      max_lost_frames);
  visitor.Visit(
      OptionField{"relocalization_candidates", "--candidates", "Best-ranked key images verified when relocalizing"}
          .Within(1, 10000),
      relocalization_candidates);
  visitor.Visit(
      OptionField{"relocalization_likelier_reach", "--relocalization-likelier-reach",
                  "Route positions from a relocalization's most verified candidate within which an accepted one "
                  "likelier by chance (lower log10 NFA, within the evidence's bound) places the frame (0 = the most "
                  "verified)"}
          .Within(0, 1000000),
      relocalization_likelier_reach);
  visitor.Visit(
      OptionField{"experience_candidates", "--experience-candidates",
                  "Maps with experiences: views of a key image verified besides it, those with the most tentative "
                  "matches (0 = the teach key images only)"}
          .Within(0, 1000)
          .Meaning("0: teach key images only"),
      experience_candidates);
  visitor.Visit(
      OptionField{"lookahead", "--lookahead", "Key images beyond the next compared while tracking (1 or 2)"}.Within(1,
                                                                                                                    2),
      lookahead);
  visitor.Visit({"lookahead_by_pace", "!--no-lookahead-by-pace",
                 "Look no further than --lookahead key images, however many teach frames the run passed a frame"},
                lookahead_by_pace);
  visitor.Visit({"step_back", "!--no-step-back", "Never move the estimate back to the previous key image"}, step_back);
  visitor.Visit(
      OptionField{"step_back_max_log10_nfa", "--step-back-max-log10-nfa",
                  "A step back to the previous key image when nothing at or ahead of the key image verifies: its log10 "
                  "NFA at most this (stricter than --max-log10-nfa: the route goes forwards)"}
          .Within(-1000, 1000),
      step_back_max_log10_nfa);
  visitor.Visit({"step_back_needs_more", "!--step-back-on-tie",
                 "Step back to the previous key image on a tie of verified matches (S decides: the earlier rule)"},
                step_back_needs_more);
  visitor.Visit({"step_back_needs_lower_nfa", "!--step-back-on-count",
                 "Step back to the previous key image on more verified matches alone, whatever their log10 NFA (the "
                 "earlier rule)"},
                step_back_needs_lower_nfa);
  visitor.Visit({"step_on_needs_more", "!--step-on-on-tie",
                 "Step on to the next key image on a tie of verified matches (S decides: the earlier rule)"},
                step_on_needs_more);
  visitor.Visit({"step_on_needs_lower_nfa", "!--step-on-on-count",
                 "ORB: step on to the next key image on more verified matches alone, whatever their log10 NFA (the "
                 "earlier rule)"},
                step_on_needs_lower_nfa);
  visitor.Visit({"step_on_by_belief", "!--no-step-on-by-belief",
                 "Never move a tracked frame on to the next key image because the belief puts it past that key "
                 "image (only the verified counts step on)"},
                step_on_by_belief);
  visitor.Visit(OptionField{"step_on_by_belief_ahead", "--step-on-by-belief-ahead",
                            "The step on by the belief (--no-step-on-by-belief): the positions past each key image "
                            "ahead whose belief is weighed against the two "
                            "at and behind the key image the tracker is at (3: the earlier rule)"}
                    .Within(1, 5),
                step_on_by_belief_ahead);
  visitor.Visit({"hold_unearned_step_on", "!--no-hold-unearned-step-on",
                 "Keep a step on the belief undoes when the key image it passed does not verify (the earlier rule)"},
                hold_unearned_step_on);
  visitor.Visit({"step_back_needs_belief", "!--no-step-back-needs-belief",
                 "Step back to the previous key image on the counts and the log10 NFA alone, whatever the belief (the "
                 "earlier rule)"},
                step_back_needs_belief);
  visitor.VisitNested("ranking", ranking);
  visitor.VisitNested("belief", belief);
  visitor.VisitNested("heading", heading);
  visitor.Section(kRulesSection);
  visitor.Visit(
      OptionField{"recheck_link_share", "--recheck-link-share",
                  "Relocalize a tracked frame with fewer verified matches than this fraction of its key image's "
                  "link, and move it where more verify (0: never)"}
          .Within(0, 10)
          .Meaning("0: never relocalize a tracked frame"),
      recheck_link_share);
  visitor.Visit(
      OptionField{"scene_change_log10_nfa", "--scene-change-log10-nfa",
                  "Float descriptors: relocalize a tracked frame whose comparison with the frame before has a log10 "
                  "NFA above this (the robot was carried), uncertain where a far place verifies more (0: never)"}
          .Within(-1000, 0),
      scene_change_log10_nfa);
  visitor.Visit(
      OptionField{"scene_change_tracked_log10_nfa", "--scene-change-tracked-log10-nfa",
                  "Ask a frame that does not share the frame before's scene again only where its tracked key image's "
                  "comparison has a log10 NFA above this (-1000: nearly every such frame)"}
          .Within(-1000, 0),
      scene_change_tracked_log10_nfa);
  visitor.Visit({"doubt_lone_step_back", "!--no-doubt-lone-step-back",
                 "Track a frame that stepped back because nothing at or ahead of the key image verified, though a far "
                 "key image verifies more (otherwise it is uncertain)"},
                doubt_lone_step_back);
  visitor.Visit({"ask_where_moved_back", "!--no-ask-where-moved-back",
                 "Float descriptors: never relocalize a tracked frame for being at a key image behind the last one a "
                 "frame was steered by (otherwise it is, and each frame after it held there)"},
                ask_where_moved_back);
  visitor.Visit({"doubt_where_moved_back", "!--no-doubt-where-moved-back",
                 "Track a frame asked where it is for being where the run moved back (--no-ask-where-moved-back) "
                 "though its relocalization finds a far key image verifying more (otherwise it is uncertain)"},
                doubt_where_moved_back);
  visitor.Visit({"ask_where_guessed_back", "!--no-ask-where-guessed-back",
                 "Float descriptors: never relocalize a tracked frame for being tracked from a guess more than two key "
                 "images behind where the last frame steered by was (otherwise it is)"},
                ask_where_guessed_back);
  visitor.Visit({"jump_needs_belief", "!--no-jump-needs-belief",
                 "Keep the tracker where a far relocalization took it though the belief withholds the frame and "
                 "guesses a place nearer where the run was last steered by (otherwise the tracker goes to the guess)"},
                jump_needs_belief);
  visitor.Visit({"doubt_jump_back", "!--no-doubt-jump-back",
                 "Float descriptors: place a frame more than two key images behind the tracked estimate even where "
                 "the key images near the estimate verify nearly as much (otherwise it is uncertain)"},
                doubt_jump_back);
  visitor.Visit({"judge_jump_back_from_steered_place", "!--no-judge-jump-back-from-steered-place",
                 "Float descriptors: doubt a frame placed behind the tracked estimate (--no-doubt-jump-back) even "
                 "where it is at or ahead of the place the run was last steered by (otherwise it is no jump back: "
                 "uncertain frames moved the tracker ahead)"},
                judge_jump_back_from_steered_place);
  visitor.Visit({"look_past_weak_next", "!--no-look-past-weak-next",
                 "Float descriptors: never look past a next key image that verifies by little beyond chance while the "
                 "tracked one does too (otherwise the key image past it is compared, and stepped on to where it "
                 "verifies more beyond chance)"},
                look_past_weak_next);
  visitor.Visit(
      OptionField{"look_past_max_log10_nfa", "--look-past-max-log10-nfa",
                  "Float descriptors: the log10 NFA at most which the key image past a weak next one must verify to be "
                  "stepped on to (--no-look-past-weak-next; -10: beyond a little chance)"}
          .Within(-1000, 0),
      look_past_max_log10_nfa);
  visitor.Visit({"step_on_to_last_by_chance", "!--no-step-on-to-last-by-chance",
                 "Float descriptors: step on to the route's last key image by the count, as to any other (otherwise "
                 "from the key image before it where it verifies at a log10 NFA lower by --step-on-to-last-lead)"},
                step_on_to_last_by_chance);
  visitor.Visit(
      OptionField{"step_on_to_last_log10_nfa_lead", "--step-on-to-last-lead",
                  "Float descriptors: how much lower a log10 NFA the route's last key image must verify at than the "
                  "tracked key image before it to be stepped on to (--no-step-on-to-last-by-chance)"}
          .Within(0, 1000),
      step_on_to_last_log10_nfa_lead);
  visitor.Visit({"doubt_relocalization_on_little_chance", "!--no-doubt-relocalization-on-little-chance",
                 "Float descriptors: steer by a frame relocalized (or tracked) more than two key images from where "
                 "the run was last steered by even where its key images verify by little beyond chance (else it is "
                 "uncertain)"},
                doubt_relocalization_on_little_chance);
  visitor.Visit(
      OptionField{"away_next_key_min_confidence", "--away-next-key-min-confidence",
                  "Float descriptors: the belief a frame placed more than two key images from where the run was last "
                  "steered by needs near it for its next key image's evidence to vouch for it (below, its own key "
                  "image must verify beyond a little chance, else it is uncertain; 0: the next key image always "
                  "vouches)"}
          .Within(0, 1),
      away_next_key_min_confidence);
  visitor.Visit(
      OptionField{"rival_place_frames", "--rival-place-frames",
                  "Frames a far key image that verified more than the one a frame was steered by is compared again; "
                  "a tracked frame it out-verifies again is relocalized (0 = never)"}
          .Within(0, 1000)
          .Meaning("0: never"),
      rival_place_frames);
  visitor.Visit(
      OptionField{"stalled_tracker_frames", "--stalled-tracker-frames",
                  "Float descriptors: frames in a row a tracker held at one key image, the next one verifying nothing "
                  "beyond a little chance, before the frame is compared with the best-ranked key images of the route "
                  "(0 = never)"}
          .Within(0, 1000)
          .Meaning("0: never"),
      stalled_tracker_frames);
  visitor.Visit(
      OptionField{"unsettled_stalled_tracker_frames", "--unsettled-stalled-tracker-frames",
                  "Float descriptors: the same for a hold that begins within two frames of a frame not steered by or "
                  "of the run's start (at most --stalled-tracker-frames; 0 = as --stalled-tracker-frames)"}
          .Within(0, 1000)
          .Meaning("0: as stalled_tracker_frames"),
      unsettled_stalled_tracker_frames);
  visitor.Visit(
      OptionField{"lagging_tracker_frames", "--lagging-tracker-frames",
                  "Float descriptors: early in the run (--lagging-start-frames), a tracker that moved on fewer "
                  "than two key images over this many frames, held by little, also compares the two key images after "
                  "the next one and steps on to one that verifies more, clearly (--look-past-max-log10-nfa; 0 = never)"}
          .Within(0, 1000)
          .Meaning("0: never"),
      lagging_tracker_frames);
  visitor.Visit(
      OptionField{
          "lagging_start_frames", "--lagging-start-frames",
          "Float descriptors: up to how many frames after the run's first a lagging tracker looks further ahead "
          "(--lagging-tracker-frames)"}
          .Within(0, 100000),
      lagging_start_frames);
  visitor.Visit({"lagging_step_weighs_belief", "!--no-lagging-step-weighs-belief",
                 "A lagging tracker's step further ahead moves the tracker only, not the belief (it weighs the place "
                 "stepped to ten to one otherwise)"},
                lagging_step_weighs_belief);
  visitor.Visit(
      OptionField{"driven_past_positions", "--driven-past-positions",
                  "With the teach run's odometry and the robot's: route positions a tracker lags where the distance "
                  "driven puts the robot before the key images there are compared, and stepped on to where one "
                  "verifies more, clearly; where it puts the robot at the tracked key image, a relocalization "
                  "further from it is not taken (0 = never, neither)"}
          .Within(0, 1000)
          .Meaning("0: never"),
      driven_past_positions);
  visitor.Visit({"rival_place_when_not_steered", "!--no-rival-place-when-not-steered",
                 "Remember and compare a far key image a lost or uncertain frame verified as a rival place too "
                 "(otherwise only frames steered by remember one)"},
                rival_place_when_not_steered);
  visitor.Visit({"rank_evidence", "!--no-rank-evidence",
                 "Never weigh the belief by the relocalization's ranking of a frame (the comparisons alone)"},
                rank_evidence);
  visitor.Visit({"rank_by_standout", "!--no-rank-by-standout",
                 "Weigh the belief by an XFeat (float-descriptor) frame's ranking by the key image's rank, not by how "
                 "far its votes stand out of the frame's (ORB's always by how far they stand out)"},
                rank_by_standout);
  visitor.Visit({"verified_ranking_steers", "!--no-verified-ranking-steers",
                 "Never steer by an ORB frame the belief doubts before the frame's own ranking, even where its key "
                 "images pass chance and the belief with its ranking singles them out"},
                verified_ranking_steers);
  visitor.Visit(
      {"steer_where_belief_stays", "!--no-steer-where-belief-stays",
       "Never steer by a frame a far place left uncertain for want of a second frame, even where the belief "
       "still singles out the tracker's place, a key image there verifies beyond a little chance and no far one "
       "verifies --min-rival-ratio times as many matches"},
      steer_where_belief_stays);
  visitor.Section("Binary descriptors (ORB): matching again where the belief points, lost frames");
  visitor.Visit({"guided_matching", "!--no-guided-matching",
                 "ORB: never match a frame again with looser matching at the key images the belief holds"},
                guided_matching);
  visitor.Visit({"guided_while_lost", "!--no-guided-while-lost",
                 "ORB: never match a frame guided at the key image the tracker held once the estimate is dropped"},
                guided_while_lost);
  visitor.Visit({"guided_relocalization", "!--no-guided-relocalization",
                 "ORB: never match a lost frame guided at the key images its relocalization ranked best"},
                guided_relocalization);
  visitor.Visit({"step_on_where_evidence_agrees", "!--no-step-on-where-evidence-agrees",
                 "ORB: never step a lost frame on to the next key image where its ranking and its heading mode agree"},
                step_on_where_evidence_agrees);
  visitor.Visit({"step_on_after_lost_frames", "!--no-step-on-after-lost-frames",
                 "ORB: never step a frame after lost frames on to the next key image where its ranking and its heading "
                 "mode agree and the frame before named it by neither"},
                step_on_after_lost_frames);
  visitor.Visit(
      OptionField{"lost_frame_features", "--lost-frame-features",
                  "ORB: a lost frame's features extracted again, this many, and compared with the ranking's best key "
                  "images extracted again likewise (0 = never)"}
          .Within(0, 100000),
      lost_frame_features);
  visitor.Visit({"lost_frame_heading", "!--no-lost-frame-heading",
                 "ORB: never accept a lost frame's comparison with more features by its heading mode standing out "
                 "against the others made so (only chance decides on them)"},
                lost_frame_heading);
  visitor.Visit(
      OptionField{"lost_frame_heading_rival_ratio", "--lost-frame-heading-rival-ratio",
                  "ORB: a lost frame's comparison with more features is accepted by its heading mode when that holds "
                  "this many times the votes of every rival among them (0: never)"}
          .Within(1, 1000)
          .Or(0)
          .Meaning("0: never"),
      lost_frame_heading_rival_ratio);
  visitor.Visit(
      OptionField{
          "lost_frame_heading_near_ratio", "--lost-frame-heading-near-ratio",
          "ORB: below --lost-frame-heading-rival-ratio, down to this, a lost frame's heading is accepted within a "
          "jump's reach of the estimate only, placed but not steered by (0: none)"}
          .Within(1, 1000)
          .Or(0)
          .Meaning("0: none"),
      lost_frame_heading_near_ratio);
  visitor.Visit(
      OptionField{
          "lost_frame_next_heading_ratio", "--lost-frame-next-heading-ratio",
          "ORB: below --lost-frame-heading-near-ratio, down to this, a lost frame's heading is accepted where it "
          "names the key image the frame before was placed at or the one after it, placed but not steered by "
          "(0: none)"}
          .Within(1, 1000)
          .Or(0)
          .Meaning("0: none"),
      lost_frame_next_heading_ratio);
  visitor.Visit(
      OptionField{"still_frame_share", "--still-frame-share",
                  "A frame whose matches with the frame before moved less than half a pixel in this share stands "
                  "still: it is not stepped on, nor placed beyond two key images of its estimate by a lost frame's "
                  "heading, nor counted in a held tracker (0: no frame is still)"}
          .Within(0, 1),
      still_frame_share);
  visitor.Visit(
      OptionField{"far_comparison_iterations", "--far-comparison-iterations",
                  "ORB: verify the frame's comparisons with key images away from the tracker's (more than one behind "
                  "or lookahead + 1 ahead) with at most this many MAGSAC iterations (0 = the verifier's)"}
          .Within(0, 10000000),
      far_comparison_iterations);
  visitor.Visit({"guided_lookahead", "!--no-guided-lookahead",
                 "ORB: match a frame guided at the key image and the next one only, ranked by verified matches (not "
                 "over the lookahead, ranked by the one-way matches' NFA where chance accepts none)"},
                guided_lookahead);
  visitor.Visit(
      OptionField{"continuity_share", "--continuity-share",
                  "ORB, guided matching: accept a comparison chance refuses when this share of its matches move as the "
                  "previous frame's heading against the key image predicts (0 = never)"}
          .Within(0, 1)
          .Meaning("0: never"),
      continuity_share);
  visitor.Visit(
      OptionField{"continuity_heading_confidence", "--continuity-heading-confidence",
                  "The continuity rule: the least share of the first comparison's matches in its heading mode"}
          .Within(0, 1),
      continuity_heading_confidence);
  visitor.Visit(OptionField{"continuity_max_log10_nfa", "--continuity-max-log10-nfa",
                            "The continuity rule: the first comparison's log10 NFA at most this"}
                    .Within(-1000, 1000),
                continuity_max_log10_nfa);
  visitor.Visit({"window_matching", "!--no-window-matching",
                 "ORB, guided matching: never match a frame again within a window around the previous frame's heading"},
                window_matching);
  visitor.Visit(
      OptionField{"window_width", "--window-width",
                  "ORB, guided matching: the window of matching by the prediction, a share of the image's width"}
          .Within(0, 1)
          .ExcludingMin(),
      window_width);
  visitor.Visit(
      OptionField{"window_zoom", "--window-zoom",
                  "ORB, matching by the prediction: the window grows by this share of a feature's distance from the "
                  "image's centre"}
          .Within(0, 10),
      window_zoom);
  visitor.Visit(
      OptionField{"window_fast_threshold", "--window-fast-threshold",
                  "ORB, matching by the prediction: the frame's FAST threshold for it (0 = the map's features)"}
          .Within(0, 255)
          .Meaning("0: the map's"),
      window_fast_threshold);
  visitor.Visit(OptionField{"window_features", "--window-features",
                            "ORB, matching by the prediction: the frame's features for it (0 = the map's number)"}
                    .Within(0, 100000)
                    .Meaning("0: the map's"),
                window_features);
  visitor.Visit(
      OptionField{"window_max_log10_nfa", "--window-max-log10-nfa",
                  "ORB, matching by the prediction: accept when the window's matches' log10 NFA is at most this"}
          .Within(-1000, 1000),
      window_max_log10_nfa);
  visitor.VisitNested("verifier", verifier, Nesting{false, {"max_samples_to_reject"}});
  visitor.Section(kRunSection);
  visitor.Visit(
      OptionField{"verifier_seed", "--verifier-seed",
                  "The seed of the verifier's sampling in the frames' comparisons (-1 = the map's verifier's)"}
          .AtLeast(-1)
          .Meaning("-1: the map's"),
      verifier_seed);
  visitor.VisitNested("translation", translation);
  visitor.Visit({"similarity"}, EnumField(similarity, kSimilarityModeNames, ParseSimilarityMode));
  visitor.Visit(OptionField{"map_tau"}.Within(0, 1), map_tau);
  visitor.Visit({"route"}, route);
  visitor.Visit(OptionField{"comparison_threads", "--comparison-threads",
                            "Threads comparing a frame with key images (1: one comparison after another); the "
                            "results do not depend on it"}
                    .NotRecorded()
                    .Within(1, 64),
                comparison_threads);
}

void LocalizerOptions::Check() const {
  CheckFieldRanges(*this);
  CheckField("ranking", ranking);
  CheckField("belief", belief);
  CheckField("verifier", verifier);
  CheckField("heading", heading);
  CheckField("translation", translation);
}

}  // namespace vmap
