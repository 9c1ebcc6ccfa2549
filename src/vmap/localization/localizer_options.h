#pragma once
// The options of the Localizer (localizer.h): how a comparison accepts a frame, how tracking and relocalization
// search the route, and what the map lends them (verifier, similarity, camera, translation thresholds). Guided
// matching's, the start's and a lost frame's second look's are in structs of their own, read as this one's (the same
// JSON paths and flags).

#include <optional>
#include <vector>

#include "vmap/core/option_fields.h"
#include "vmap/geometry/camera.h"
#include "vmap/geometry/fundamental.h"
#include "vmap/geometry/heading.h"
#include "vmap/geometry/translation_evidence.h"
#include "vmap/localization/acceptance.h"
#include "vmap/localization/key_image_ranking.h"
#include "vmap/localization/localizer_guided_options.h"
#include "vmap/localization/localizer_lost_frame_options.h"
#include "vmap/localization/localizer_start_options.h"
#include "vmap/localization/route_belief.h"
#include "vmap/mapping/key_image_selector.h"

namespace vmap {

struct LocalizerOptions : GuidedMatchingOptions, StartOptions, LostFrameOptions {
  // When a comparison accepts the frame at a key image (acceptance.h, docs/localization-acceptance.md).
  // kChance (default): matching and verification succeed, the verified set is unlikely by chance (log10 of its
  // number of false alarms, every comparison a frame can make counted as a test, at most `max_log10_nfa`; 0:
  // what chance would explain less than once over all the comparisons of a frame: the same scene), and it holds
  // at least `min_link_share` times the verified matches of the key image's link with its route neighbour (the
  // smaller of its two links: what two neighbouring key images of this map share, so the bar follows the
  // matcher, the image size and the texture: the same place).
  // kCounts (the earlier rule): at least `min_verified` verified matches and S >= `min_similarity` (S as the map
  // defines it), whatever the matcher and image size.
  // Chance alone says "the same scene", which a far key image of the same room also is; the link share adds "the
  // same place". The defaults were chosen on redkitchen's teach/repeat test (docs/localization-acceptance.md; the
  // figures: docs/measurements/code-choices.md, "Accepting a frame at a key image").
  AcceptanceRule acceptance = AcceptanceRule::kChance;
  double max_log10_nfa = 0.0;
  double min_link_share = 0.4;  // 0: chance alone decides (a key image without a link on the route: likewise)
  // The link share's reference on a map built with a tau above this (`map_tau`; `--tau 1`: neighbours nearly one image,
  // whose link verifies about twice what a frame of another run does at the right key image): a key image's link as a
  // map of this tau would hold it, found when the localizer starts (link_share_reference.h). 0: the map's matcher's
  // default tau (FollowMap gives it; a Localizer given 0 keeps the map's links); 1: the map's links always.
  double link_share_tau = 0.0;
  // The tau the map's key images were selected with (its key_images.tau; follows the map, FollowMap); 0: not known.
  double map_tau = 0.0;
  int min_verified = 20;
  double min_similarity = 0.3;
  // Across seasons the link share refuses the right key image: the map's links are of one season, and a frame of
  // another verifies a fraction of their matches there (michigan textures in the simulator: 0.17-0.33 of them, at
  // log10 NFA -390 to -1015). A comparison refused by the link share alone is then judged against the frame's own
  // rivals: accepted when its log10 NFA is at most `rival_max_log10_nfa` and it verifies at least `min_rival_ratio`
  // times as many matches as every key image compared with the frame more than two route positions from it (the
  // best-ranked such key image always among them: compared when it was not). Tracking judges each tracked key image
  // so; a relocalization that accepts none judges the one with the most verified matches. A frame at a place the
  // map does not hold has no key image standing out so far above the others. 0: never (kChance only; how the
  // defaults were measured: docs/localize.md, "Acceptance against the frame's rivals").
  double min_rival_ratio = 2.0;
  double rival_max_log10_nfa = -100.0;
  // Across seasons ORB's verified sets at the right key image rarely pass chance, yet its matches still agree on one
  // displacement there (the heading mode: 30-60 of them where a wrong place's modes hold at most 15, michigan_seasons).
  // A comparison whose heading mode holds at least `min_heading_votes` matches and at least `min_heading_rival_ratio`
  // times the heading votes of every rival the frame was compared with is accepted where chance refused it (never
  // where the link share refuses it: a frame seen from elsewhere sees the scene's matches agree too). Its
  // rivals: the key images compared more than two route positions away, and nearer ones the map's links do not join
  // to it by a scene (a link chance refuses: a route of unrelated places), the best-ranked rival always among them.
  // Binary descriptors only (fitted on ORB; XFeat's modes were not measured). 0: never (docs/localize.md, "A heading
  // that stands out against the frame's rivals").
  double min_heading_rival_ratio = 2.0;
  int min_heading_votes = 12;
  // Same scene is not same place. A frame tracked at a key image with fewer verified matches than
  // `recheck_link_share` times those of the key image's link (as above) is also relocalized, and moved to the
  // ranked key image that verifies more matches, if one does: a frame that verifies against a far key image of
  // the same room must not stay there. 0: never (tracking keeps any accepted key image).
  double recheck_link_share = 0.5;
  // A robot carried elsewhere (a kidnapping, a stretch the camera did not see) still verifies a few chance matches at
  // the key image it left: across lighting XFeat accepts them there (corridor_conditions' kidnapped run at the
  // verifier's seed 1: frame 51, carried 30 frames on, tracked on 16 verified at log10 NFA -0.25, 10 key images off).
  // Consecutive frames of a moving robot share their scene far beyond chance (XFeat, the corridor at seeds 0-3: log10
  // NFA -50 to -190 between a frame and the one before; -5 to -16 where the run was carried). A tracked frame whose
  // comparison with the frame before (the map's matcher, verified as a key image's) has a log10 NFA above this is
  // relocalized as one sharing little with its key image is, and is `uncertain`, not steered by, where a far place
  // verifies more (the jump itself still needs two frames: Localizer::TakesJump). Float descriptors only (XFeat; ORB
  // was not measured). 0: never (docs/measurements/localization-conditions.md, "XFeat over the verifier's seeds 4-7,
  // and three rules measured, none kept", rule 2).
  double scene_change_log10_nfa = -30.0;
  // ... and only where the tracked key image's own comparison with the frame has a log10 NFA above this: a frame held
  // there by little beyond chance. A michigan_seasons route's places never share a scene, so there the frame before
  // asks every frame again, and a right frame tracked far beyond chance (02 -> 03 frame 2: -320) had its step on undone
  // by its ranking (with rank_by_standout, michigan XFeat at the verifier's seed 0: 653 -> 646 right and not uncertain,
  // 6 -> 11 wrong). The frames the rule is for are tracked at -0.25 to -6.1 (the kidnapped run's frame 51 after the
  // carry; michigan 03 -> 08's places 4 and 5 at seed 2); the right frames it undid, at -13.8 to -2546
  // (docs/measurements/localization-conditions.md, "Rules 2 and 3 together, rule 2 narrowed": michigan at seed 0 653
  // -> 655, 6 -> 2 wrong; the corridor's sets as the rule unnarrowed at seeds 0-7). -1000: nearly every tracked frame.
  double scene_change_tracked_log10_nfa = -10.0;
  // A lone step back (taken because nothing at or ahead of `key` verified, `key` refused by chance itself and not only
  // by the link share: the key image the frames were at no longer sees the frame's scene) is `uncertain`, not tracked,
  // when that frame's relocalization (above) finds a key image verifying more far away (a jump one frame does not make:
  // Localizer::TakesJump). The tracker keeps the key image behind, as a lost frame keeps the estimate, but a robot
  // carried elsewhere must not be steered by the place it left while the frames after it decide (docs/localize.md, "A
  // lone step back is doubted"). Off: it is tracked there.
  bool doubt_lone_step_back = true;
  // Float descriptors (XFeat): a tracked frame at a key image behind the last one a frame was steered by (the run moved
  // back: a step back, a relocalization behind, a robot carried back), and each frame after it tracked there, is
  // relocalized as one that shares little with its key image is, until the tracker leaves that key image. The route
  // goes forwards, and across lighting XFeat verifies as much at a key image where the corridor repeats itself as at
  // the right one: corridor_conditions' key image 3 (teach frame 9) verifies 19-30 matches at log10 NFA -5 to -27 with
  // repeat frames 20-34 (right: key images 4-10). Moved back there, the tracker compares only the key images after it,
  // which verify less, and is held (the kidnapped run at the verifier's seed 6: 7 frames steered by 3-5 key images
  // behind); its relocalization compares the ranking's best key images and their neighbours, and moves the frame to
  // one that verifies more (a far one still takes two frames: Localizer::TakesJump). A frame steered by where the
  // frames before were, or ahead of them, is not asked (docs/measurements/localization-conditions.md, "A frame where
  // the run moved back is asked where it is": XFeat over the verifier's seeds 0-7, frames confidently more than 2 key
  // images off 17 -> 3, the corridor and michigan at seeds 0-3 as before). Off: such a frame is asked as any other is.
  bool ask_where_moved_back = true;
  // ... and such a frame is `uncertain`, not steered by, where its relocalization finds a far key image verifying more
  // (the place the run moved back to is doubted as the place a carried robot left is: doubt_lone_step_back). Seeds 0-7:
  // 3 -> 1 far frames (the corridor from frame 20 at seed 5), 5 right frames uncertain in 48 runs.
  bool doubt_where_moved_back = true;
  // Float descriptors (XFeat): a tracked frame whose tracker starts more than two route positions behind where the last
  // frame steered by was (uncertain frames moved it there: a far relocalization not yet taken, the belief) is
  // relocalized as one that shares little with its key image is, and moved where it verifies more nearby; a far place
  // verifying more leaves it tracked (the frames before were not steered by: no move back of the run's to doubt).
  // Across lighting the guess is often a look-alike behind: the kidnapped run's repeat frame 22 was tracked at key
  // image 3 (right: 4-6) from the uncertain frames before at 19 of the verifier's seeds 0-31 (docs/measurements/
  // localization-conditions.md, "A frame tracked from a guess behind is asked where it is"). Off: asked as any other.
  bool ask_where_guessed_back = true;
  // Float descriptors (XFeat): a frame placed more than two route positions behind the tracked estimate (a
  // relocalization or a move of the belief behind it) is `uncertain`, and the tracker stays, where an accepted key
  // image within two route positions of the estimate, verifying beyond a little chance (log10 NFA at most -10),
  // verified at least 0.7 times the matches of the place the frame jumped to. The route goes forwards, and across
  // lighting XFeat verifies as much at corridor_conditions' key image 3 as at the right key images 7-8 (repeat frame 30
  // at the verifier's seed 10: key image 3 32 matches at log10 NFA -22.0, key image 8 30 at -19.7; relocalized back
  // there, frames 30-33 were steered by 4-6 key images off). A jump back no clearer than where the frames were is the
  // look-alike's as likely as the robot's (docs/measurements/localization-conditions.md, "A jump back no clearer than
  // where the frames were is doubted": XFeat's corridor sets over the verifier's seeds 0-11, frames confidently more
  // than 2 key images off 17 -> 11, 69 of 72 CSVs the same). Off: such a frame is placed where it jumped.
  bool doubt_jump_back = true;
  // A jump the belief withholds is not the tracker's: the tracker goes to the belief's guess where that is nearer the
  // place last steered by (docs/localize.md; seed 256's frame 55). Off: it stays where the jump took it.
  bool jump_needs_belief = true;
  // Float descriptors (XFeat), doubt_jump_back: a jump back is judged from the place the run was last steered by too,
  // not only from the tracked estimate: a frame placed at or ahead of that place (or at most two route positions
  // behind it) is no jump back, wherever uncertain frames left the tracker. After corridor_conditions' dark stretch an
  // unconfirmed relocalization left the tracker at key image 29-30 (the route's end, whose key images verify with
  // nearly every frame through the lens rim's matches) while the run was last steered by at 14; frames 56-60 verified
  // 24-35 matches at the right key images 15-16 at log10 NFA -10 to -32, each doubted as a jump back from 30, and the
  // tracker stayed there for five frames (the verifier's seed 106; docs/measurements/localization-conditions.md, "A
  // jump back is judged from where the run was steered": over the verifier's seeds 0-19 and 32-139, 14 of 768 CSVs
  // change, each a frame withheld or wrong now steered by at a right key image). Off: judged from the tracked estimate
  // alone.
  bool judge_jump_back_from_steered_place = true;
  // Float descriptors (XFeat): where the lookahead stops at a next key image that verifies by little beyond chance
  // (log10 NFA above -10, or refused) while the tracked key image does too, the key image past it is compared, and the
  // tracker steps on to it where it verifies more matches than the tracked one, beyond a little chance (log10 NFA at
  // most -10). Across lighting a next key image that sees little of the frame (corridor_conditions' key image 5, teach
  // frame 23) held the tracker at the look-alike key images 3-4 behind it while the key image past it (6) verified
  // 25-29 matches at -15 to -17, and repeat frame 30 was steered by 3 key images behind (docs/measurements/
  // localization-conditions.md, "A tracker held at a look-alike looks past a weak next key image": XFeat's corridor
  // sets over the verifier's seeds 0-15, frames confidently more than 2 key images off 11 -> 3). Off: the lookahead
  // stops at the first key image that does not beat the tracked one.
  bool look_past_weak_next = true;
  // Float descriptors (XFeat), look_past_weak_next: the key image past the weak next one is stepped on to only where it
  // verifies clearly, at log10 NFA at most this (-10: beyond a little chance, the rule as it was first written). The
  // key image past that mends a tracker held at a look-alike verifies at -15.3 to -16.9 (corridor_conditions' key
  // image 6 on repeat frames 26-27 of the corridor from 20, the verifier's seeds 8, 9, 14, 16 and 18), while 9 of the
  // 10 steps one key image early at repeat frames 90-94 of the corridor (to key image 31, teach frame 101, where 28-29
  // are right) were taken at -10.2 to -11.5 over seeds 0-19 (docs/measurements/localization-conditions.md, "The look
  // past needs the key image past to verify clearly": the corridor's right and not uncertain 104.10 -> 104.95 a seed).
  double look_past_max_log10_nfa = -13.0;
  // Float descriptors (XFeat): the tracker at the key image before the route's last steps on to the last one where it
  // verifies at a log10 NFA lower than the tracked key image's by step_on_to_last_log10_nfa_lead, whatever the count
  // (and never by the count alone). Nothing lies past the route's last key image: on corridor_conditions' last segment
  // XFeat verifies more matches with the key image before it on the frames past it (repeat frame 110, where only the
  // last is right, was steered by at the one before at 15 of the verifier's seeds 0-31) and a few more with the last
  // on frames 97-99, a key image early (23 times), while chance tells them apart the right way
  // (docs/measurements/localization-conditions.md, "The route's last key image is stepped on to by chance"). Off:
  // stepped on to by the count, as every other key image.
  bool step_on_to_last_by_chance = true;
  // step_on_to_last_by_chance: how much lower (in log10 NFA) the route's last key image must verify than the tracked
  // one. 6 (a millionth): at 4-5 the tracker steps on at corridor_conditions' repeat frame 97 at seed 8 (28 matches at
  // -17.9 against 28 at -12.9), a key image early.
  double step_on_to_last_log10_nfa_lead = 6.0;
  // Float descriptors (XFeat): a frame relocalized more than two route positions from where the run was last steered
  // by, at key images that verify by little beyond chance (neither at a log10 NFA of at most -10), is `uncertain`.
  // Across lighting such a relocalization is a look-alike's more often than the robot's: over XFeat's corridor sets at
  // the verifier's seeds 0-27, 12 of the 46 relocalizations so were right and 2 were more than 2 key images off (the
  // corridor's dark stretch, repeat frame 54 at key image 30 where 14-15 are right, seed 26), the rest 1-2 off
  // (docs/measurements/localization-conditions.md, "A relocalization away on little chance is doubted"). So is a frame
  // tracked that far on such key images where uncertain frames or the frame moved the tracker more than two from there
  // (seed 48's corridor from repeat frame 20: frame 53 at key image 31 at -8.2, right: 14-15; "A frame tracked away on
  // little chance is doubted"; "Tracked on from near the place steered by"). Off: such a frame is steered by.
  bool doubt_relocalization_on_little_chance = true;
  // With doubt_relocalization_on_little_chance: the next key image's evidence vouches for such a frame only where the
  // belief holds at least this near it; below, the key image the frame is steered by must itself verify beyond a
  // little chance. corridor_conditions' dark repeat frame 55 (right: key images 14-16) was placed at key image 29 at
  // log10 NFA -7.5 to -9.3 on the strength of key image 30's -15.4, with 0.55-0.74 of the belief near it, 15 key images
  // from where the run was last steered (the verifier's seeds 87, 165 and 167); over seeds 0-19 the 4 right frames
  // placed so far with less than 0.9 near them verified their own key image at -14.6 to -29.3
  // (docs/measurements/localization-conditions.md, "A far place vouched for by its next key image needs the belief").
  // 0: the next key image vouches whatever the belief.
  double away_next_key_min_confidence = 0.9;
  // A place elsewhere on the route that verified more matches than the key images a frame was steered by (a key image
  // more than two route positions away) is a rival: for this many frames it is compared again (it and the key image
  // after it), and a tracked frame it out-verifies again is relocalized, as a frame that shares little with its key
  // image is. Where the corridor repeats itself, a wrong place verifies as much as a right one, and is questioned
  // only when something else is compared (docs/localize.md, "A rival place is asked again"). 0: never.
  int rival_place_frames = 3;
  // Float descriptors (XFeat): a tracker held this many frames in a row at one key image, each steered by while the
  // next key image verified nothing beyond a little chance (log10 NFA above -6), is questioned: the frame is ranked
  // over the route and compared with the best-ranked key images, whose evidence weighs the belief, as a
  // relocalization's would. A key image that verifies everywhere (corridor_conditions' 12-13, where a quarter to two
  // thirds of a frame's verified matches are the fisheye's rim matching itself) otherwise holds a robot that started
  // elsewhere: the kidnapped run from its frame 51 at the verifier's seed 75 was tracked there for 21 frames (repeat
  // frames 90-110, right: 27-32) and never compared anywhere else. On XFeat's corridor sets at seeds 0-7 the tracker
  // held so at most 6 frames in a row at a right key image (docs/measurements/localization-conditions.md, "A tracker
  // held where the next key image sees nothing is questioned"). A still frame (still_frame_share: a robot that stopped)
  // neither adds to the hold nor is questioned: its ranking, the same on every frame of a stop, would be weighed again
  // as new. 0: never.
  int stalled_tracker_frames = 7;
  // A hold that begins within two frames of a frame not steered by (lost or uncertain) or of the run's start is
  // questioned at this many frames instead (at most stalled_tracker_frames): a place just taken rests on a frame or two
  // of evidence, not on a run of them. The kidnapped run from its frame 51 at the verifier's seed 75 confirms its start
  // at key image 12, one of the key images that verify everywhere, and is held at 12-13 from the next frame: questioned
  // at the seventh frame, 7 frames were steered by there (right: 27-31), at the third 3. Over the verifier's seeds
  // 0-19 and 68-115 (408 runs) it changes 7 runs: the runs started elsewhere +10 frames at a right key image, the
  // kidnapped run -2, and 4 fewer far frames (docs/measurements/localization-conditions.md, "A hold that begins after a
  // frame not steered by is questioned sooner"). 0: as stalled_tracker_frames.
  int unsettled_stalled_tracker_frames = 3;
  // Float descriptors (XFeat): up to lagging_start_frames frames after the run's first, a tracker that moved on fewer
  // than two key images over the last this many frames, held at a key image that verifies the frame by less than
  // clearly (log10 NFA above look_past_max_log10_nfa), also compares the two key images after the next one, and steps
  // on to the better of them where it verifies more matches than the tracked one, clearly. A run's first place rests on
  // a frame or two of evidence, and the start key image's prior holds the belief behind it: a robot further on than
  // --start-key says may be placed short, at a look-alike of where it is, and the tracker compares only the key images
  // just after it. corridor_conditions from repeat frame 20 is started at key image 2 (right: 4-5) at every seed; key
  // image 3 (teach frame 9) verifies nearly every frame to repeat frame 33 while the next ones see little, and at the
  // verifier's seeds 54, 127, 136 and 153 the tracker was still at 3-4 on repeat frames 27-31 (right: 6-8): 6 frames
  // steered by more than two key images off. Looking further on frame 26 or 27 it finds key image 6 at log10 NFA -16 to
  // -18 and steps on. Only at the start: a tracker that followed the route, or was relocalized after a carry, is as
  // slow where key images lie far apart (corridor_conditions' 27-29 at repeat frames 84-95), and the key images further
  // on there, the route's end, are look-alikes that verify clearly (docs/measurements/localization-conditions.md, "A
  // tracker lagging the run's start looks further ahead"). 0: never.
  int lagging_tracker_frames = 6;
  // lagging_tracker_frames: a tracker is asked so up to this many frames after the run's first.
  int lagging_start_frames = 10;
  // The lagging tracker's step weighs the belief too, ten to one at the key image stepped to: the start key image's
  // prior still holds the belief behind the tracker, and a frame after the step that shares little with its key image
  // (where key images lie far apart) was relocalized back to the look-alike, where the belief still was
  // (corridor_conditions from repeat frame 20, the verifier's seed 188: stepped on from key image 3 to 5 on frame 26,
  // frame 29 verified key image 7 at log10 NFA -3.6 and was relocalized back at 3, frame 32 tracked at 2, both steered
  // by; right: 6-8). Weighed, the belief holds 0.87 near key image 5 on frame 26 rather than 0.65, frame 29 stays at 7
  // and frames 31-36 are steered by at 8. Ten to one, as a lost frame's ranking and heading agreeing weigh it: the step
  // is the tracker's move, which the frame's comparisons, weighed as any, do not tell the belief
  // (docs/measurements/localization-conditions.md, "A lagging tracker's step moves the belief too"). Off: the step
  // moves the tracker only.
  bool lagging_step_weighs_belief = true;
  // Where the route's key images have the teach run's odometry and the frames the robot's (the motion model's pace by
  // the distance driven), a tracker this many route positions or more behind where the distance driven puts the robot
  // compares the key images there (the one the teach odometry puts nearest and its two neighbours) and steps on to the
  // best of them where it verifies more matches than the tracked key image, clearly (log10 NFA at most
  // look_past_max_log10_nfa), the belief weighed there ten to one as a lagging tracker's step weighs it. The distance
  // is counted from where the tracker last stepped on to a key image at or ahead of the odometry's place, or was
  // relocalized. The tracker compares only its key image and the next, and a look-alike of the place the robot
  // reached keeps verifying there while the robot drives on: corridor_conditions' repeat at one to four times the
  // teach speed against its map of places was held at key image 29, a look-alike of the route's end, over its last
  // three frames (right: 32-36) at the verifier's seeds 3 and 11, while key images 33 and 35 verified 38 and 47
  // matches at log10 NFA -24 and -48 where the odometry put the robot (docs/measurements/localization-conditions.md,
  // "A tracker behind the distance driven looks where the odometry says"). Where the distance driven puts the robot
  // within a route position of the tracker's key image, it also vouches for it: a relocalization the frame is asked
  // for (SharesLittle and the other doubts of Track) that would take the tracker further from that place is not taken
  // on that frame, whatever it verifies: the seed's noise makes a near tie of a look-alike a few key images back
  // (the same run at the verifier's seed 7: repeat frame 20 relocalized back to key image 3 on 29 verified matches
  // against 28 at key image 6, right: 6-8, where the odometry put the robot; "The distance driven vouches for the
  // tracked key image"). 0: never, neither rule.
  int driven_past_positions = 2;
  // A frame not steered by (lost or uncertain) remembers a rival place too: any far key image its comparisons accepted
  // (it verifies more than the frame's key images, which verify nothing a robot may steer by), and compares the one
  // remembered, as a tracked frame does. A robot carried along the route verifies nothing where the tracker holds it,
  // and the ranking's five seldom hold its new place twice in a row: once verified there, the place is asked again and
  // its evidence weighs the belief until the belief moves the estimate there (docs/localize.md, "A rival place is
  // asked again while the frames are not steered by"). Off: only frames steered by remember one.
  bool rival_place_when_not_steered = true;
  // Where a frame was ranked (a relocalization, a question of the belief, a rival), the ranking weighs the belief too:
  // each key image by its bucket in the ranking, and a comparison by what it adds to its bucket (EvidenceModel::
  // rank_alone; fitted on every pair of corridor_conditions: docs/localize.md, "The ranking is evidence"). Both by how
  // far a key image's votes stand out of the frame's (XFeat's: rank_by_standout); ORB's at half the joint model, after
  // the belief's rules moved the tracker: the frame's own ranking only withholds it ("ORB's ranking only withholds its
  // own frame"). Off: the comparisons alone weigh it.
  bool rank_evidence = true;
  // XFeat's (float descriptors') ranking weighs the belief by how far a key image's votes stand out of the frame's, as
  // ORB's, not by its rank: a dark frame's first key image whose votes barely stand out (65 against 62, 61, ...) is
  // no place, and by rank it moved the belief to the corridor's end in one frame (corridor_conditions XFeat over the
  // verifier's seeds 0-7: frames confidently > 2 key images off 5 -> 0; docs/localize.md, "XFeat's ranking by how its
  // votes stand out"). Off: by rank, as before.
  bool rank_by_standout = true;
  // ORB's frame that only the belief before its own ranking doubts is steered by where its comparison at its key images
  // passes chance, the belief with its ranking singles that place out (the peak within two key images) and the tracker
  // is there: the frame's verified evidence and its ranking agree, and what doubted it is mass the frames before left
  // elsewhere (corridor_conditions frame 47: steered by at key image 19, whose next key image 20 its relocalization
  // verified a frame after key image 16 stopped verifying, the belief before its ranking still at 15; docs/localize.md,
  // "A frame verified where its ranking puts it"). Off: doubted as before.
  bool verified_ranking_steers = true;
  // A frame left uncertain because a far place it verified needs a second frame (TakesJump) is steered by where the
  // belief, the frame's evidence weighed, still singles out a place within two key images of the tracker and not
  // behind the place the run was last steered by, and a comparison there verifies beyond a little chance (log10 NFA at
  // most -10; the link share aside) while no far comparison verifies min_rival_ratio times as many matches (a far place
  // that stands out so is a robot carried off): a far place the belief does not follow is no reason to doubt the place
  // it holds (docs/localize.md, "A far place the belief does not follow"). Off: uncertain as before.
  bool steer_where_belief_stays = true;
  // Key images compared beyond `next_key` when the frame has passed it (1 or 2: the "next one or two").
  int lookahead = 2;
  // The lookahead reaches the key images within the teach frames the run passed since the frame before, and where it
  // passed the whole lookahead every key image of it is compared (MotionPace::Lookahead, PassedLookahead;
  // docs/localize.md, "The lookahead where key images crowd"). Off: `lookahead` key images, the first that verifies
  // no more than the best ending the look.
  bool lookahead_by_pace = true;
  // While tracking, also compare the key image before `key` when the frame is nearer `key` than `next_key`
  // (fewer than a third of their verified matches are with `next_key`), and move back when it is the better
  // match: the frame may be behind `key`. A check that finds it clearly worse is repeated on the frames that
  // follow only once their verified matches with `next_key` fall below that frame's (they moved back). Off: the
  // estimate only moves forwards (a robot that never reverses).
  bool step_back = true;
  // A step back when neither `key` nor the key images ahead verify (nothing there to weigh it against) needs the key
  // image behind to verify at a log10 NFA of at most this, stricter than chance's `max_log10_nfa`: the route goes
  // forwards, so a key image behind that verifies at the edge of chance is likelier chance than a step back. -1: about
  // the motion model's odds against a step back rather than staying (0.05 / 0.55; docs/localize.md).
  double step_back_max_log10_nfa = -1.0;
  // A step back needs more verified matches than the key image or the key image ahead it would replace: on a tie
  // (which S would decide) the estimate stays, since the route goes forwards and two key images a frame apart that
  // verify as many matches are a coin toss (corridor_conditions frame 17: back to key image 4 on 0.01 of S, and the
  // next frame on again). Off: the better match by IsBetterMatch, a tie decided by S (docs/localize.md).
  bool step_back_needs_more = true;
  // A step back from a key image that verifies needs its verified matches less likely by chance too (a lower log10
  // NFA) than those of the key image it would replace: the count and the a-contrario test must agree before the route
  // goes backwards. Off: the count alone decides.
  bool step_back_needs_lower_nfa = true;
  // A step on needs more verified matches than the key image it would leave behind (or the key image ahead it would
  // pass): on a tie the frame is as near one as the other, midway on the segment it is on, so the estimate stays.
  // Across lighting XFeat verifies 20-30 matches at every key image around the frame, and key images a teach frame
  // apart tie often (corridor_conditions frames 32 and 95 went on a key image early on S). Off: the better match by
  // IsBetterMatch, a tie decided by S (docs/localize.md).
  bool step_on_needs_more = true;
  // With binary descriptors (ORB), a step on needs the key image ahead's verified matches less likely by chance too (a
  // lower log10 NFA) than those of the key image it would leave or pass: a frame a teach frame or two short of the next
  // key image verifies about as many matches at both, and the count alone went on early and the next frame stepped back
  // (corridor_conditions frame 103). Float descriptors (XFeat) verify chance matches at most key images, where the NFA
  // ranks nothing: off for them whatever this says. Off: the count alone decides (docs/localize.md).
  bool step_on_needs_lower_nfa = true;
  // A frame tracked at a key image the belief puts behind it moves on: where the belief, after the frame's evidence,
  // holds more on the segments past the next key image than on the segment it is on and the one before, and that key
  // image verifies, the tracker steps on to it (up to `lookahead` key images). Across lighting XFeat verifies as many
  // matches at the key image left behind as at the one reached, so the count alone keeps the tracker where it was.
  // Only where the ranking weighs the belief (`rank_evidence`, XFeat): ORB's belief holds nothing the counts did not
  // (docs/localize.md, "A key image the belief puts behind is left"). Off: only the counts step on.
  bool step_on_by_belief = true;
  // step_on_by_belief: the belief on this many positions from the key image ahead is weighed against the belief on the
  // two at and behind the key image the tracker is at: as many on each side. Three against two moved the tracker on by
  // the windows' widths alone where the belief is spread (a run's first frames across lighting): corridor_conditions at
  // the verifier's seed 241, the tracker stepped on from key image 5 to 6, 7 and 9 on repeat frames 21-23 with the
  // belief's peak at 4, and frame 23 was steered by at 9 (right: 4-6). Over seeds 232-255 two against two: the corridor
  // 104.21 -> 104.50 a seed, the kidnapped run 95.25 -> 95.54, started elsewhere 194.04 -> 194.38, far frames 2 -> 0;
  // held out, seeds 184-231: 104.38 -> 104.54, 96.25 -> 96.42, 191.31 -> 191.46
  // (docs/measurements/localization-conditions.md, "The belief's step on weighs as many positions on each side").
  // 3: the rule as it was before 2026-12-04.
  int step_on_by_belief_ahead = 2;
  // A step on the belief undoes (Localizer::SettleStepOn: after the frame's evidence it holds more behind the key image
  // left than past the one reached) is undone also when the key image it passed does not verify: the tracker stays on
  // the segment before the key image reached, tracking (that key image, now `next_key`, verified). Across lighting the
  // key image passed often does not verify while one ahead does (ORB's guided matching over the lookahead:
  // corridor_conditions frame 49 went on to key image 21 while the belief held 0.016 there, and the next frame stepped
  // back). Only where the map's link between the two key images is of one scene (a --tau 1 map of unrelated places has
  // no segment between them). Off: such a step on stays (docs/localize.md).
  bool hold_unearned_step_on = true;
  // A step back (Track's, or the recheck's relocalization within two key images behind) is undone when the belief,
  // after the frame's evidence, holds more on the segment past the key image left than on the segment before the key
  // image reached (and than a flat belief), holds `min_confidence` near the key image left, and that key image
  // verifies: the mirror of a step on that needs the belief. Not where the key image reached verifies beyond the
  // evidence's bound (the same scene beyond doubt: a hand-held camera that reverses in the same season). Off: the
  // counts and the log10 NFA alone step back (docs/localize.md).
  bool step_back_needs_belief = true;
  // A lost frame steps on where its own weak evidence agrees (ORB maps): a frame that nothing verifies, relocalized or
  // guided, right after a frame placed (tracking or relocalized) at the tracked key image, moves on to the key image
  // after it when the frame's ranking puts that key image first and its heading mode holds more votes there than at any
  // other key image compared, each strictly (a tie singles out nothing). Across seasons (michigan_seasons) chance
  // refuses most right key images, and each of the two measures of the frame's likeness names a wrong key image often
  // (the ranking's first is wrong in 63 % of the lost frames); both together, at the one key image a robot seen at the
  // one before reaches next, have not. The frame's own evidence must name that key image, so a robot that stops is not
  // walked on by the motion prior (docs/measurements/localization-conditions.md, "A lost frame steps on where its
  // ranking and its heading agree"). Such a frame is placed, not steered by: its heading is that of comparisons chance
  // and the heading rule refused (guidance "none"; "The frames it places are not steered by"). Off: such a frame is
  // lost.
  bool step_on_where_evidence_agrees = true;
  // The same after lost frames (ORB maps): a frame that nothing verifies, after one or more frames lost at the tracked
  // key image, moves on to the key image after it where its ranking and its heading mode agree on it as above, and the
  // frame before named it by neither (a robot that stops shows the same place again, which names the same key image).
  // The frames lost before it left the belief where chance put it: the agreement is weighed there first, ten times
  // likelier at the right key image than at a wrong one on michigan_seasons' lost frames. Placed, not steered by, as
  // above (docs/measurements/localization-conditions.md, "A frame after lost frames steps on where its evidence
  // agrees"). Off: such a frame is lost.
  bool step_on_after_lost_frames = true;
  // A frame stands still where at least this share of its matches with the frame before (the map's matcher, unverified)
  // moved less than half a pixel: stopped frames of michigan_seasons, the corridor and lab_floor, identical or with a
  // camera's noise, 281 / 281 pairs at 0.8; moving ones 2 / 397, none at the corridor's repeat (at most 0.26 of its
  // matches so). The rule above does not step a still frame on to the key image after the frame before's, nor do the
  // agreement rules (step_on_where_evidence_agrees, step_on_after_lost_frames: the only steps of a stopped robot the
  // stop check measured on main; docs/measurements/localization-conditions.md, "A still frame after lost frames is not
  // stepped on either"), nor is a still frame placed by a lost frame's heading beyond kNear of its estimate, at any
  // ratio above (its votes are the frame before's evidence counted again: 24 noisy copies of a stopped michigan frame,
  // 22 frames placed three key images on -> 1, by chance; "A still frame is not placed far by a lost frame's
  // heading"), nor does it add to a held tracker (stalled_tracker_frames). 0: no frame is still.
  double still_frame_share = 0.8;
  // ORB: the frame's comparisons with key images away from the tracker's (more than one route position behind the
  // estimate the frame starts from, or more than `lookahead` + 1 ahead of it: the frame's rivals, the ranking's
  // candidates, the belief's window elsewhere) are verified with at most this many MAGSAC iterations, not the
  // verifier's 5,000. Across lighting nearly all are refused (corridor_conditions' sets: 6 of 830 accepted), each after
  // all 5,000 (MAGSAC's confidence is never reached on a third of ~54 matches), yet each is read: the rules that accept
  // a tracked key image against its rivals, and the belief. At 2,000 every figure holds (michigan ORB 503 -> 508) and
  // corridor ORB takes 8 % less CPU; at 1,500 and below the corridor's sets lose frames (docs/measurements/
  // localization-conditions.md, "Fewer iterations for the comparisons away from the tracker"). 0: every comparison
  // with the verifier's.
  int far_comparison_iterations = 2000;
  // Lost frames in a row (each one also failed to relocalize) after which the estimate is dropped: key and
  // next_key then read -1 until a frame is relocalized.
  int max_lost_frames = 5;
  // Best-ranked key images verified when relocalizing.
  int relocalization_candidates = 5;
  // Among the accepted candidates within this many route positions of the one that verified the most, the likeliest
  // by chance (lowest log10 NFA, clamped at the evidence's bound as NoLikelierChance has it: beyond it the count
  // decides) is where a relocalization places the frame. Across lighting a key image the frame has passed verifies more
  // of the scene than the one it is at (corridor_conditions with XFeat at the verifier's seed 3: frame 21 at key image
  // 3, 25 verified, where key image 5 verified 18 at a lower NFA; frames 21-32 held 2-3 key images behind). 0: the most
  // verified.
  int relocalization_likelier_reach = 2;
  RankingOptions ranking;
  // The belief over the route (route_belief.h): its motion model and when a frame is uncertain.
  RouteBeliefOptions belief;
  // The map's verifier (as map.json records it), except that localization caps its iterations (see
  // MapVerifierOptions): a frame that shares little with a key image must fail fast.
  VerifierOptions verifier;
  // The seed of that verifier's random sampling in the frames' comparisons, ORB's and XFeat's alike (FollowMap sets
  // verifier.seed to it); -1: the map's. ORB's near comparisons sit at chance's boundary (a third of ~54 matches
  // inliers on the corridor): another seed flips ~6 % of their decisions and moves corridor ORB's right frames by
  // 5-7 (sd), so a rule worth a few frames is judged over several seeds (bench/route_conditions.py --seeds;
  // docs/measurements/localization-conditions.md, "The verifier's seed: the spread of every figure").
  int verifier_seed = -1;
  SimilarityMode similarity = SimilarityMode::kInlierRatio;
  // Key-image indices to follow, in order (PlanRoute gives one); empty = every key image in map order.
  std::vector<int> route;
  // How the heading to each key image compared is estimated (geometry/heading.h).
  HeadingOptions heading;
  // The map's camera (map.input.camera: intrinsics from the dataset or --camera). With it each comparison
  // also gives the heading in degrees and the relative pose to the key image; without, pixels only.
  std::optional<Camera> camera;
  // When a pose's translation direction is trusted (the map's link_analysis.translation: MapLocalizerOptions).
  TranslationOptions translation;
  // Maps with experiences (map/experiences.h): views of a key image verified besides the key image itself,
  // those with the most tentative matches with the frame (matching is cheap, verification is not). 0: the
  // teach key images only. 2 by default: a frame rarely fits more than the one or two views of its season.
  int experience_candidates = 2;
  // How a run is carried out, not what it decides: threads comparing a frame with key images, the Localizer's own
  // included. Those beyond it make the comparisons the frame is about to make meanwhile (speculative_comparisons.h),
  // with the same results. 1: no thread of its own, one comparison after another.
  int comparison_threads = 2;

  // As a localization run records them (its "options"; not the camera, which the map gives) and the flags of
  // `vmap localize`. The verifier, the translation thresholds, the similarity and map_tau follow the map
  // (MapVerifierOptions, FollowMap): they are recorded, but have no flags here (the verifier's seed has its own,
  // verifier_seed), and the verifier records no early stop (localization verifies each comparison in full).
  void VisitFields(OptionFieldVisitor& visitor);
  void Check() const;  // throws OptionError naming the bad field
};

}  // namespace vmap
