#include "vmap/geometry/sampson_error.h"

namespace vmap::internal {

void PointColumns::Assign(const std::vector<Point>& points) {
  const std::size_t n = points.size();
  x0.resize(n), y0.resize(n), x1.resize(n), y1.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    x0[i] = points[i].x0, y0[i] = points[i].y0, x1[i] = points[i].x1, y1[i] = points[i].y1;
  }
}

// Compiled with -fno-trapping-math (geometry/CMakeLists.txt): with trapping math GCC 12 keeps the selects below
// as branches and vectorises nothing. The option changes no value, only whether FP exceptions may be raised by
// lanes whose result is then not selected.
__attribute__((target_clones("avx2", "default"))) void SquaredSampsonErrors(const Model& f, const PointColumns& points,
                                                                            int begin, int end, double* r2) {
  const double* x0 = points.x0.data() + begin;
  const double* y0 = points.y0.data() + begin;
  const double* x1 = points.x1.data() + begin;
  const double* y1 = points.y1.data() + begin;
  const int count = end - begin;
  const Model model = f;  // a copy r2 cannot alias: its entries stay in registers
  for (int i = 0; i < count; ++i) {
    const EpipolarTerms terms = EpipolarTermsOf(model.data(), x0[i], y0[i], x1[i], y1[i]);
    const bool positive = terms.gradient_norm2 > 0;
    const double quotient = terms.residual * terms.residual / (positive ? terms.gradient_norm2 : 1.0);
    r2[i] = positive ? quotient : std::numeric_limits<double>::infinity();
  }
}

}  // namespace vmap::internal
