// Medians of plain samples, the one place the library takes them.
//
//   - upper_median(v): the element at index n/2 of the sorted values, the upper of the middle
//     two for an even count. It is always one of the samples, which is what a frame period or a
//     ring spacing wants (a real gap, never the mean of two).
//   - median(v): the mean of the middle two for an even count (a statistic to report).
//   - median_step(t): the upper median of the steps between consecutive values (a frame
//     period from frame times).
// Each returns 0 for no samples (median_step: fewer than two values). Each takes O(n) with
// std::nth_element on its own copy; the value returned does not depend on the input's order.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace ulc {

inline double upper_median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

inline double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  if (values.size() % 2 == 1) return *middle;
  return 0.5 * (*middle + *std::max_element(values.begin(), middle));
}

inline double median_step(const std::vector<double>& values) {
  if (values.size() < 2) return 0.0;
  std::vector<double> steps;
  steps.reserve(values.size() - 1);
  for (std::size_t i = 1; i < values.size(); ++i) steps.push_back(values[i] - values[i - 1]);
  return upper_median(std::move(steps));
}

}  // namespace ulc
