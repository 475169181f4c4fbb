#pragma once
// Wall-clock milliseconds for the figures the tool reports (build, refit,
// trace and frame times): std::chrono::steady_clock, never the system clock;
// and the median that the repeated runs of a figure report.
#include <algorithm>
#include <chrono>
#include <vector>

namespace accelviz {

/// Milliseconds from `t0` (a steady_clock time point) to now.
inline double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

/// Median of the values (the mean of the two middle ones for an even count); 0 if empty.
inline double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace accelviz
