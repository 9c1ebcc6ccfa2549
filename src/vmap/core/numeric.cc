#include "vmap/core/numeric.h"

#include <algorithm>
#include <cmath>

namespace vmap {

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const size_t middle = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + middle, values.end());
  const double upper = values[middle];
  if (values.size() % 2 == 1) return upper;
  return 0.5 * (upper + *std::max_element(values.begin(), values.begin() + middle));
}

double MedianOrNan(const std::vector<double>& values) { return values.empty() ? NAN : Median(values); }

double MedianOfFinite(const std::vector<double>& values) {
  std::vector<double> finite;
  for (double v : values) {
    if (std::isfinite(v)) finite.push_back(v);
  }
  return MedianOrNan(finite);
}

double MeanOfFinite(const std::vector<double>& values) {
  double sum = 0;
  int count = 0;
  for (double v : values) {
    if (std::isfinite(v)) {
      sum += v;
      ++count;
    }
  }
  return count > 0 ? sum / count : NAN;
}

double ShareBelow(const std::vector<double>& values, double threshold) {
  if (values.empty()) return NAN;
  size_t count = 0;
  for (double v : values) count += v < threshold ? 1 : 0;
  return static_cast<double>(count) / values.size();
}

}  // namespace vmap
