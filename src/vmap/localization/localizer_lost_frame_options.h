#pragma once
// A lost frame's second look (ORB maps): compared again with more features, and accepted by a heading that stands out
// among those comparisons (LocalizerOptions derives from it; localizer_options.cc gives the fields' flags).

namespace vmap {

struct LostFrameOptions {
  // A lost frame compared again with more features (ORB maps whose key image files are at hand): a frame that verifies
  // nothing at the tracked key images, nor at the ranking's best when relocalized, guided too, has its features
  // extracted again, `lost_frame_features` of them, and is compared with the ranking's best key images
  // (relocalization_candidates) whose first comparison chance refused and the link share did not, their features
  // extracted again likewise from the map's key image files (once each, when first needed). It is relocalized again on
  // what chance accepts of them (max_log10_nfa, as any comparison), and a place far from the tracked estimate still
  // needs two frames (TakesJump). Across seasons 500 features match too few of a right key image's for chance
  // (michigan_seasons' lost ORB frames verify 14 of 147 tentative matches at their right key image, as many as at the
  // wrong ones); with 4,000 on both sides 26 of its 274 lost frames are placed at their place, none elsewhere
  // (docs/measurements/localization-conditions.md, "A lost frame compared again with more features"). 0: never.
  int lost_frame_features = 4000;
  // Where chance accepts none of those comparisons with more features, the one whose heading mode stands out against
  // the others made so is accepted as a heading that stands out against the frame's rivals is (min_heading_votes,
  // min_heading_rival_ratio, the link share; its rivals among the comparisons with more features only: 4,000 features
  // give any key image's mode more votes than 500 do). michigan_seasons' lost ORB frames: their right key image's mode
  // holds 31 votes (median), the best wrong one's 18 (docs/measurements/localization-conditions.md, "A lost frame's
  // heading with more features"). Off: only chance decides on them.
  bool lost_frame_heading = true;
  // That rule's ratio, in place of min_heading_rival_ratio (whose 0 still turns both off): with 4,000 features a
  // lost frame's right key image stands out less against its best rival than at 500, and no wrong one reaches even
  // 1.5 times its rivals on the sets measured (docs/measurements/localization-conditions.md, "A lost frame's heading
  // with a ratio of its own"). 0: never.
  double lost_frame_heading_rival_ratio = 1.75;
  // Below that ratio, down to this one, the lost frame's heading is accepted only where the route's order expects the
  // frame, within a jump's reach ahead of the estimate it starts from (Localizer::JumpReach: kNear, plus lookahead for
  // each frame lost since; behind it kNear only: lost frames move the robot on), and the frame is placed but not
  // steered by. At 1.5 without the reach the corridor's frame 20 accepted key image 10, four ahead of its estimate,
  // and the belief spread (two frames uncertain); within it michigan_seasons' frames placed so are at their place, but
  // 7 of their 20 headings are more than 35 px off the hand label (docs/measurements/localization-conditions.md, "A
  // lost frame's heading near where the route expects it").
  // 0: none below lost_frame_heading_rival_ratio.
  double lost_frame_heading_near_ratio = 1.5;
  // Below that ratio, down to this one, the lost frame's heading is accepted where the route's order expects the frame
  // after one placed at the estimate: the frame before was placed at the estimate the frame starts from, and the
  // heading names that key image or the one after it; the frame is placed, not steered by. michigan_seasons' lost ORB
  // frames after a placed one: at 1.2 36 such headings name their place and none another (1.15: 38 / 1; within a
  // jump's reach, as the near ratio asks, 46 / 10: the wrong ones name the key image before the estimate, or are a
  // run's first frames), and the route's order is a motion prior: a robot that stops and shows its place again may be
  // stepped on, which a frame standing still (still_frame_share) is not (docs/measurements/
  // localization-conditions.md, "A lost frame's heading where the route goes next, and a robot that stops"). 0: none.
  double lost_frame_next_heading_ratio = 1.2;
};

}  // namespace vmap
