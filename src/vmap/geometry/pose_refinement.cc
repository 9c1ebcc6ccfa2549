#include "vmap/geometry/pose_refinement.h"

#include <algorithm>
#include <cmath>

#include <opencv2/calib3d.hpp>

#include "vmap/geometry/sampson_error.h"

namespace vmap {

namespace {

// The pose R0 exp([w]x), t = normalise(t0 + d0 b0 + d1 b1) around a start pose; parameters (w, d).
class PoseOnManifold {
 public:
  PoseOnManifold(const cv::Matx33d& R0, const cv::Vec3d& t0) : R0_(R0), t0_(cv::normalize(t0)) {
    const cv::Vec3d axis = std::abs(t0_[0]) < 0.9 ? cv::Vec3d(1, 0, 0) : cv::Vec3d(0, 1, 0);
    b0_ = cv::normalize(t0_.cross(axis));
    b1_ = t0_.cross(b0_);
  }
  void At(const double* x, cv::Matx33d* R, cv::Vec3d* t) const {
    cv::Matx33d dR;
    cv::Rodrigues(cv::Vec3d(x[0], x[1], x[2]), dR);
    *R = R0_ * dR;
    *t = cv::normalize(t0_ + x[3] * b0_ + x[4] * b1_);
  }

 private:
  cv::Matx33d R0_;
  cv::Vec3d t0_, b0_, b1_;
};

// Robust Sampson residuals (pixels, Cauchy-weighted) of matches under the pose at parameters x.
class SampsonCost : public cv::LMSolver::Callback {
 public:
  SampsonCost(const PoseOnManifold& manifold, std::vector<cv::Point2d> from, std::vector<cv::Point2d> to, double focal,
              double scale)
      : manifold_(manifold), from_(std::move(from)), to_(std::move(to)), focal_(focal), scale_(scale) {}

  bool compute(cv::InputArray param, cv::OutputArray err, cv::OutputArray J) const override {
    const cv::Mat x = param.getMat();
    CV_Assert(x.total() == 5 && x.type() == CV_64F);
    err.create(static_cast<int>(from_.size()), 1, CV_64F);
    Residuals(x.ptr<double>(), err.getMat().ptr<double>());
    if (J.needed()) {
      // Central differences: five parameters, a few hundred matches.
      J.create(static_cast<int>(from_.size()), 5, CV_64F);
      cv::Mat jacobian = J.getMat();
      std::vector<double> plus(from_.size()), minus(from_.size());
      for (int k = 0; k < 5; ++k) {
        double shifted[5];
        std::copy(x.ptr<double>(), x.ptr<double>() + 5, shifted);
        constexpr double h = 1e-7;
        shifted[k] += h;
        Residuals(shifted, plus.data());
        shifted[k] -= 2 * h;
        Residuals(shifted, minus.data());
        for (size_t i = 0; i < from_.size(); ++i)
          jacobian.at<double>(static_cast<int>(i), k) = (plus[i] - minus[i]) / (2 * h);
      }
    }
    return true;
  }

 private:
  void Residuals(const double* x, double* out) const {
    cv::Matx33d R;
    cv::Vec3d t;
    manifold_.At(x, &R, &t);
    const cv::Matx33d E = CrossMatrix(t) * R;
    for (size_t i = 0; i < from_.size(); ++i) {
      const double r = focal_ * SignedSampsonError(E, from_[i], to_[i]);
      // sqrt of the Cauchy loss's weight: least squares on these minimises sum log(1 + (r / scale)^2).
      out[i] = r / std::sqrt(1.0 + (r / scale_) * (r / scale_));
    }
  }

  PoseOnManifold manifold_;
  std::vector<cv::Point2d> from_, to_;
  double focal_, scale_;
};

}  // namespace

std::vector<double> PoseSampsonErrors(const cv::Matx33d& R, const cv::Vec3d& t, const NormalizedMatches& matches) {
  const cv::Matx33d E = CrossMatrix(t) * R;
  std::vector<double> errors;
  errors.reserve(matches.size());
  for (size_t i = 0; i < matches.size(); ++i) {
    errors.push_back(std::abs(matches.focal() * SignedSampsonError(E, matches.from[i], matches.to[i])));
  }
  return errors;
}

std::vector<double> PoseSampsonErrors(const cv::Matx33d& R, const cv::Vec3d& t, const Camera& camera,
                                      const std::vector<cv::Point2f>& from, const std::vector<cv::Point2f>& to) {
  return PoseSampsonErrors(R, t, NormalizedMatches(camera, from, to));
}

std::vector<unsigned char> MatchesWithin(const RelativePose& pose, const NormalizedMatches& matches, double threshold) {
  std::vector<unsigned char> mask;
  for (double e : PoseSampsonErrors(pose.R, pose.t, matches)) mask.push_back(e < threshold ? 1 : 0);
  return mask;
}

RelativePose RefineRelativePose(const RelativePose& pose, const NormalizedMatches& matches, double inlier_threshold,
                                double loss_scale) {
  if (!pose.valid) return pose;
  NormalizedMatches inliers = matches.Select(MatchesWithin(pose, matches, inlier_threshold));
  if (inliers.size() < 5) return pose;
  const PoseOnManifold manifold(pose.R, pose.t);
  cv::Ptr<SampsonCost> cost =
      cv::makePtr<SampsonCost>(manifold, std::move(inliers.from), std::move(inliers.to), matches.focal(), loss_scale);
  cv::Mat x = cv::Mat::zeros(5, 1, CV_64F);
  cv::LMSolver::create(cost, 50)->run(x);
  RelativePose refined = pose;
  manifold.At(x.ptr<double>(), &refined.R, &refined.t);
  if (!cv::checkRange(cv::Mat(refined.R)) || !cv::checkRange(cv::Mat(refined.t))) return pose;
  const std::vector<double> refined_errors = PoseSampsonErrors(refined.R, refined.t, matches);
  refined.num_inliers = static_cast<int>(
      std::count_if(refined_errors.begin(), refined_errors.end(), [&](double e) { return e < loss_scale; }));
  return refined;
}

RelativePose RefineRelativePose(const RelativePose& pose, const Camera& camera, const std::vector<cv::Point2f>& from,
                                const std::vector<cv::Point2f>& to, double inlier_threshold, double loss_scale) {
  if (!pose.valid) return pose;
  return RefineRelativePose(pose, NormalizedMatches(camera, from, to), inlier_threshold, loss_scale);
}

double TranslationSigmaDeg(const RelativePose& pose, const NormalizedMatches& matches, double inlier_threshold,
                           double loss_scale) {
  constexpr double kUnknown = 180.0;
  if (!pose.valid) return kUnknown;
  NormalizedMatches inliers = matches.Select(MatchesWithin(pose, matches, inlier_threshold));
  const int n = static_cast<int>(inliers.size());
  if (n < 8) return kUnknown;
  const SampsonCost cost(PoseOnManifold(pose.R, pose.t), std::move(inliers.from), std::move(inliers.to),
                         matches.focal(), loss_scale);
  cv::Mat residuals, jacobian;
  cost.compute(cv::Mat::zeros(5, 1, CV_64F), residuals, jacobian);
  // Residual variance with the five parameters' degrees of freedom taken out; at least (0.1 px)^2 so that
  // noise-free matches do not claim a certainty the pixels cannot give.
  const double variance = std::max(residuals.dot(residuals) / (n - 5), 0.01);
  cv::Mat covariance;
  if (cv::invert(jacobian.t() * jacobian, covariance, cv::DECOMP_SVD) <= 0) return kUnknown;
  // The two translation parameters are tangent displacements of the unit t: radians of its direction.
  const cv::Mat block = covariance(cv::Rect(3, 3, 2, 2)) * variance;
  cv::Mat eigenvalues;
  cv::eigen(block, eigenvalues);
  const double largest = eigenvalues.at<double>(0);
  if (!std::isfinite(largest) || largest < 0) return kUnknown;
  return std::min(kUnknown, std::sqrt(largest) * 180.0 / CV_PI);
}

double TranslationSigmaDeg(const RelativePose& pose, const Camera& camera, const std::vector<cv::Point2f>& from,
                           const std::vector<cv::Point2f>& to, double inlier_threshold, double loss_scale) {
  if (!pose.valid) return 180.0;
  return TranslationSigmaDeg(pose, NormalizedMatches(camera, from, to), inlier_threshold, loss_scale);
}

}  // namespace vmap
