#include "harness/stats.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace geodex::bench {

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const size_t rank = static_cast<size_t>(std::ceil(q * static_cast<double>(v.size())));
  return v[std::min(v.size(), std::max<size_t>(rank, 1)) - 1];
}

double MaxOf(const std::vector<double>& v) {
  return v.empty() ? std::nan("") : *std::max_element(v.begin(), v.end());
}

double MinOf(const std::vector<double>& v) {
  return v.empty() ? std::nan("") : *std::min_element(v.begin(), v.end());
}

double RelDiff(double a, double b) {
  if (a == b) return 0;
  return std::abs(a - b) / std::abs(b);
}

double LargestFinite(const std::vector<double>& distance) {
  double largest = 0;
  for (double d : distance) {
    if (std::isfinite(d)) largest = std::max(largest, d);
  }
  return largest;
}

}  // namespace geodex::bench
