#pragma once
// Small statistics over values that every stage uses (parallax, headings, displacements, `vmap eval`'s
// summaries): written once, with what each returns when there is nothing to summarise.

#include <vector>

namespace vmap {

// The median: the middle value, or the mean of the two middle values of an even count. 0 for no values.
double Median(std::vector<double> values);
// The median, NaN for no values.
double MedianOrNan(const std::vector<double>& values);
// The median of the finite values (NaN and infinities left out), NaN when there is none.
double MedianOfFinite(const std::vector<double>& values);
// The mean of the finite values, NaN when there is none.
double MeanOfFinite(const std::vector<double>& values);
// The share of values below `threshold`, NaN for no values.
double ShareBelow(const std::vector<double>& values, double threshold);

}  // namespace vmap
