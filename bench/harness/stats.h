#pragma once

// Summaries of repeated measurements and of distance fields.

#include <limits>
#include <vector>

namespace geodex::bench {

inline constexpr double kInf = std::numeric_limits<double>::infinity();

// The median (the mean of the two middle values for an even count); 0 for none.
double Median(std::vector<double> v);
// The value at the nearest rank q (0 < q <= 1) of v; NaN for none.
double Quantile(std::vector<double> v, double q);
// The largest and the smallest value; NaN for none.
double MaxOf(const std::vector<double>& v);
double MinOf(const std::vector<double>& v);
// |a - b| / |b|, 0 when both are equal (also both infinite).
double RelDiff(double a, double b);
// The largest finite value, 0 if none is larger.
double LargestFinite(const std::vector<double>& distance);

}  // namespace geodex::bench
