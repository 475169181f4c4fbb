#pragma once
// Wall-clock milliseconds for the figures the tool reports (build, refit,
// trace and frame times): std::chrono::steady_clock, never the system clock.
#include <chrono>

namespace accelviz {

/// Milliseconds from `t0` (a steady_clock time point) to now.
inline double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace accelviz
