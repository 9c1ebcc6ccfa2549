#pragma once
// The visual map: key images and the links between consecutive key images (García-Pintos et al. 2023).

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vmap/core/enum_names.h"
#include "vmap/map/experiences.h"
#include "vmap/sources/frame_source.h"

namespace vmap {

struct KeyImage {
  int frame_index = 0;      // index in the processed sequence
  int source_index = 0;     // index in the input
  double timestamp = -1.0;  // seconds; -1 when the input has none
  std::string source_name;  // image file name or "frame_000123"
  std::string image_file;   // relative to the map directory, e.g. "keys/000012.png"
  int num_features = 0;
  std::string reason;  // why it was chosen (first frame, similarity drop, matching failed, final frame)
};

struct Correspondence {
  cv::Point2f p0;  // in the link's first key image
  cv::Point2f p1;  // in the link's second key image
};

// The p0 and the p1 of the first `count` correspondences (all when count < 0): the two point lists the geometry
// functions take.
void SplitCorrespondences(const std::vector<Correspondence>& correspondences, std::vector<cv::Point2f>* points0,
                          std::vector<cv::Point2f>* points1, int count = -1);

// Two consecutive key images and what ties them together.
struct Link {
  int from_key = 0;  // index into VisualMap::key_images
  int to_key = 0;
  // The frame right after the first key image already fell below tau (or could not be matched), so that
  // frame became the second key image: the link joins two consecutive frames and its S is below tau. Its F
  // is as good as any (null only when matching failed). Called `broken` in maps of schema version 1.
  bool below_tau = false;
  double similarity = 0.0;  // S of the paper
  int num_tentative = 0;    // matches that entered verification
  int num_verified = 0;     // inliers of F
  bool has_fundamental = false;
  cv::Matx33d F = cv::Matx33d::zeros();  // x_to^T F x_from = 0, in pixels
  // The tentative matches, verified ones first: [0, num_verified) are inliers, the rest were rejected.
  std::vector<Correspondence> correspondences;

  // What a robot needs to trust the link (see mapping/link_analysis.h; filled when the map is built).
  // The relative pose, when the camera is known: X_to = R X_from + t, |t| = 1 (geometry/relative_pose.h).
  bool has_pose = false;
  cv::Matx33d R = cv::Matx33d::eye();
  cv::Vec3d t;
  int pose_inliers = 0;  // matches consistent with the pose
  // How well the matches determine t's direction: its standard deviation in degrees with the rotation
  // marginalised (geometry/relative_pose.h, TranslationSigmaDeg). < 0: not computed (maps written before it).
  double translation_sigma_deg = -1.0;
  // How much more the cheapest other minimum of the pose's cost, with a translation more than the map's
  // link_analysis.translation.rival_angle_deg away, costs (geometry/relative_pose.h, RivalCostGap).
  // < 0: no such minimum was found (or not computed: maps written before it, poses from F).
  double translation_rival_cost_gap = -1.0;
  // t's direction is to be trusted (translation_sigma_deg and parallax within the map's
  // link_analysis.translation, geometry/translation_evidence.h TranslationKnown); otherwise a robot gets the
  // rotation only. False without a pose; maps written before the field say nothing and read as has_pose.
  bool translation_known = false;
  // Median displacement of the verified matches in pixels: after undoing the rotation R when there is a pose
  // (what the translation's direction rests on), the plain displacement otherwise. < 0: not computed.
  double parallax = -1.0;
  bool parallax_without_rotation = false;  // parallax is the rotation-compensated one
  // Share of the verified matches that one homography explains as well as F does; `planar` when it is at
  // least HomographyOptions::min_share (a plane or a pure rotation: F and the pose are ill-posed). < 0: not
  // computed.
  double homography_share = -1.0;
  bool planar = false;
};

// One comparison S(key, frame) made while building: what a user looks at to choose tau. A new field goes into
// the build's evaluations file too (map_writer.cc, ForEachRecordField; kEvaluationRecordSize).
struct Evaluation {
  int key_frame = 0;
  int frame = 0;
  double similarity = 0.0;
  int num_tentative = 0;
  int num_verified = 0;
  bool matched = false;  // matching and verification succeeded (S is meaningful)
};

struct MapStatistics {
  int num_frames = 0;      // n
  int num_key_images = 0;  // m
  int min_verified = 0;    // over links
  int max_verified = 0;
  double mean_verified = 0.0;
  double mean_similarity = 0.0;
  double quality = 0.0;     // Q
  int below_tau_links = 0;  // links whose S is below tau (Link::below_tau)
};

// Which frames of the input a map covers and why it ends there: recorded (map.json "coverage") for maps
// of live runs, whose input has no known end: a snapshot written while the run went on, or a map finished when
// SIGINT ended the input (`vmap build --until-interrupted`).
enum class CoverageEnd { kInputEnded, kInterrupted, kSnapshot };
inline constexpr EnumName<CoverageEnd> kCoverageEndNames[] = {{CoverageEnd::kInputEnded, "input ended"},
                                                              {CoverageEnd::kInterrupted, "interrupted"},
                                                              {CoverageEnd::kSnapshot, "snapshot"}};
struct Coverage {
  int num_frames = 0;           // frames processed
  int first_source_index = -1;  // the first and last of them, as indices in the input (-1: none)
  int last_source_index = -1;
  CoverageEnd end = CoverageEnd::kInputEnded;
};

struct VisualMap {
  SequenceInfo input;
  std::string options_json;  // every option used, as JSON text
  int num_frames = 0;
  int skipped_frames = 0;  // corrupt frames skipped while reading
  std::vector<KeyImage> key_images;
  std::vector<Link> links;
  std::vector<Evaluation> evaluations;
  double quality = 0.0;
  double seconds = 0.0;              // wall time of the build
  std::optional<Coverage> coverage;  // absent for a map of a whole input (file, folder, dataset)
  // Other runs of the route added to the map (map/experiences.h); checked by ReadMap like every other field.
  std::vector<Experience> experiences;
  // Where features may be (features/camera_mask.h): CV_8UC1 of input.frame_size, 0 where none may be, 255
  // elsewhere; empty for a map built without a camera mask. Written as kCameraMaskFileName beside map.json.
  cv::Mat camera_mask;
};

enum class QualityMean { kArithmetic, kHarmonic };
inline constexpr EnumName<QualityMean> kQualityMeanNames[] = {{QualityMean::kArithmetic, "arithmetic"},
                                                              {QualityMean::kHarmonic, "harmonic"}};
QualityMean ParseQualityMean(const std::string& name);
std::string QualityMeanName(QualityMean mean);

// Q(M) = mean of (1 - m/n) and the mean similarity of consecutive key images (arithmetic by default:
// the paper's formula and tables; its text says harmonic). With no link the mean similarity is 0.
double MapQuality(int num_frames, int num_key_images, const std::vector<double>& link_similarities, QualityMean mean);

MapStatistics ComputeStatistics(const VisualMap& map, QualityMean mean);

}  // namespace vmap
