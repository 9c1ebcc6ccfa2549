#include "vmap/geometry/sampson_errors.h"

namespace vmap::internal {

void PointColumns::Assign(const std::vector<Point>& points) {
  const std::size_t n = points.size();
  x0.resize(n), y0.resize(n), x1.resize(n), y1.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    x0[i] = points[i].x0, y0[i] = points[i].y0, x1[i] = points[i].x1, y1[i] = points[i].y1;
  }
}

__attribute__((target_clones("avx2", "default"))) void SquaredSampsonErrors(const Model& f, const PointColumns& points,
                                                                            int begin, int end, double* r2) {
  const double* x0 = points.x0.data() + begin;
  const double* y0 = points.y0.data() + begin;
  const double* x1 = points.x1.data() + begin;
  const double* y1 = points.y1.data() + begin;
  const int count = end - begin;
  const double f0 = f[0], f1 = f[1], f2 = f[2], f3 = f[3], f4 = f[4], f5 = f[5], f6 = f[6], f7 = f[7], f8 = f[8];
  for (int i = 0; i < count; ++i) {
    const double l0 = f0 * x0[i] + f1 * y0[i] + f2;
    const double l1 = f3 * x0[i] + f4 * y0[i] + f5;
    const double l2 = f6 * x0[i] + f7 * y0[i] + f8;
    const double m0 = f0 * x1[i] + f3 * y1[i] + f6;
    const double m1 = f1 * x1[i] + f4 * y1[i] + f7;
    const double e = x1[i] * l0 + y1[i] * l1 + l2;
    const double d = l0 * l0 + l1 * l1 + m0 * m0 + m1 * m1;
    const bool positive = d > 0;
    const double quotient = e * e / (positive ? d : 1.0);
    r2[i] = positive ? quotient : std::numeric_limits<double>::infinity();
  }
}

}  // namespace vmap::internal
