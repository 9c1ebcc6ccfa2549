#pragma once
// The pace at which a run passes the route's key images: how many times a frame applies the route belief's motion
// model (RouteBeliefOptions). The model was fitted where the run passed a key image every third frame; a run that
// passes one every frame (a map of places, a frame rate a third of the teach run's, a node that drops frames while it
// localizes) must move the belief three times as far a frame, or the belief stays behind its evidence
// (docs/localize.md, "The motion model's pace").
//
// Where both runs have odometry (the teach run's beside its map, the repeat's with each frame), the distance driven
// between two frames says how far the run went, whatever its speed. Else a run is taken to pass the route at the
// teach run's speed (a teach-and-repeat robot's): the time between two frames says how far it went when both runs
// have timestamps, whatever either's frame rate; else the input indices do, which assumes the teach run's frame rate
// too.

#include <optional>
#include <vector>

#include "vmap/sources/odometry_sample.h"

namespace vmap {

// The motion model's steps per route position passed: it was fitted on corridor_conditions' default XFeat map (key
// images 3.4 teach frames apart on average), localized frame by frame: one step a frame (any spacing from 2.25
// teach frames up still gives one step a frame).
inline constexpr double kMotionStepsPerPosition = 3.0;
// No frame is moved by more steps than this: a long gap in the input (a stretch of a video not decoded, a robot
// that stood still without frames) spreads the belief no further than eight steps do, and costs no more.
inline constexpr int kMaxMotionSteps = 8;

// The mean spacing of a route's consecutive key images in the teach input: their input indices (`source_index`,
// which --stride leaves as the input's) or their timestamps. The mean, not the median: a handheld camera's bursts of
// key images a frame apart are not the whole route's pace. A route may run backwards through the map. 0 (unknown)
// for a route of fewer than two key images; for timestamps also when a key image has none (below 0) or the times do
// not all rise or all fall along the route (key images of several recordings).
double TeachFramesPerPosition(const std::vector<int>& route_source_indices);
double TeachSecondsPerPosition(const std::vector<double>& route_timestamps);
// The mean distance driven between a route's consecutive key images: `route_distances`, the teach odometry's metres
// driven at each key image in route order (NaN: the odometry does not cover it), over the key images it covers. 0
// (unknown) where it covers fewer than two, where their distances do not all grow (or all shrink: a route backwards
// through the map) along the route, or where the odometry did not move between them.
double TeachMetresPerPosition(const std::vector<double>& route_distances);

// The motion model's steps for a frame that went `travelled` since the frame before, in the unit of
// `teach_per_position` (input frames, seconds or metres): kMotionStepsPerPosition per position passed, rounded, 1 to
// kMaxMotionSteps. 1 where either is unknown (not above 0).
int MotionStepsPerFrame(double travelled, double teach_per_position);

// A run's pace, frame by frame: by the distance driven where the route's key images have teach odometry and both
// frames odometry, else by time where the route's key images and both frames have timestamps that rise, else by
// input index.
class MotionPace {
 public:
  MotionPace() = default;  // one step a frame
  // The route's key images' input indices and timestamps (below 0: none), in route order; `fixed_steps` above 0:
  // that many steps every frame but the first (RouteBeliefOptions::motion_steps_per_frame).
  MotionPace(const std::vector<int>& route_source_indices, const std::vector<double>& route_timestamps,
             int fixed_steps = 0);

  // The teach odometry's metres driven at each of the route's key images, in route order (TeachMetresPerPosition;
  // NaN: not covered).
  void SetTeachDistances(const std::vector<double>& route_distances);
  bool by_distance() const { return teach_metres_per_position_ > 0.0; }

  // The next frame starts a run: it is one step from the start (how far it is from a frame before is not known).
  void Reset();
  // The motion model's steps for the run's next frame, at input index `source_index`, time `timestamp` (below 0:
  // none) and the robot's odometry pose `odometry` (none: the robot has no odometry at that time). The distance
  // driven between two frames is the straight line between their odometry poses: frames are close enough in time
  // that the path between them is straight, and a robot's odometry gives its pose, not a running distance.
  int Steps(int source_index, double timestamp, const std::optional<OdometrySample>& odometry = std::nullopt);
  // How many key images past route position `position` the tracker compares on the run's last frame (given to Steps):
  // `lookahead`, or more where the key images after the next one crowd within the teach frames the run passed since
  // the frame before (by time, distance or index, as Steps; the key images' input indices give the teach frames). A
  // repeat at three times the teach speed, or at a third of its frame rate, passes three teach frames a frame, and
  // where the teach run made a key image every frame (rccar_room's fast turn) three key images: a lookahead of two
  // leaves it behind (docs/localize.md, "The lookahead where key images crowd"). At most kMaxMotionSteps.
  int Lookahead(int position, int lookahead) const;
  // Whether the run passed, since the frame before, more than a teach frame and every key image of the `lookahead`
  // after the next one: the frame may then be past any of them, and one that verifies a little less than the key image
  // before it says nothing of those after it (Localizer::Track compares them all).
  bool PassedLookahead(int position, int lookahead) const;

  // The metres the robot drove since the first frame of the current stretch of frames that each had odometry, summed
  // over the straight lines between them, up to the last frame Steps was given; none where that frame had no odometry.
  // A stretch that lost its odometry begins again at 0: differences are taken within one stretch only
  // (driving_stretch()).
  std::optional<double> metres_driven() const;
  int driving_stretch() const { return driving_stretch_; }

  // Where on the teach run the distance driven puts the robot, where the pace is by the distance driven: counted from
  // a route position's key image (CountDrivenFrom) and taken onto a segment of the route (PlaceDrivenOnSegment), both
  // at the last frame Steps was given. The teach odometry's metres there; none where the count was not begun, the
  // frame had no odometry, or the stretch of odometry it was begun in ended.
  std::optional<double> teach_metres_driven() const;
  // Counts the distance driven from route position `position`'s key image: forgotten where the teach odometry does
  // not cover it or the frame had no odometry.
  void CountDrivenFrom(int position);
  // Takes the count onto the segment from route position `position` to the next (its key image's teach metres where
  // the next is not covered or there is none): where it is on the segment it stays, else it is moved to the nearer
  // end. Nothing where the count is not known.
  void PlaceDrivenOnSegment(int position);
  // Whether the teach odometry covers route position `position`'s key image (where the pace is by the distance
  // driven).
  bool Covers(int position) const;
  // The route position whose teach odometry is nearest `teach_metres` (-1: none covered).
  int NearestPosition(double teach_metres) const;
  // The route position whose teach odometry is nearest teach_metres_driven() (-1: not known).
  int DrivenPosition() const;

 private:
  std::vector<int> route_source_indices_;
  double teach_frames_per_position_ = 0.0;
  double teach_seconds_per_position_ = 0.0;
  double teach_metres_per_position_ = 0.0;
  int fixed_steps_ = 0;
  bool started_ = false;  // a frame of the run was seen: the two below are its
  int source_index_before_ = 0;
  long teach_frames_passed_ = 0;    // whole, on the last frame: 0 where not known (the first frame, a fixed pace)
  double timestamp_before_ = -1.0;  // below 0: none
  std::optional<OdometrySample> odometry_before_;
  double metres_driven_ = 0.0;
  int driving_stretch_ = 0;
  // The teach odometry's metres at each route position where the pace is by the distance driven (else empty), and
  // whether they grow (1) or shrink (-1) along the route.
  std::vector<double> route_teach_metres_;
  int route_teach_direction_ = 0;
  // Where the count of the distance driven began: the teach metres the robot was taken to be at, the robot's
  // metres_driven() then and their stretch.
  struct DrivenFrom {
    double teach_metres = 0.0;
    double metres = 0.0;
    int stretch = -1;
  };
  std::optional<DrivenFrom> driven_from_;
};

}  // namespace vmap
