// core/util/timing.h: the median that every repeated figure reports (bench,
// calibrate, sweep, the GUI's sweep worker, the GPU benchmark).
#include <gtest/gtest.h>

#include <vector>

#include "core/util/timing.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace accelviz::unity_test_timing {
namespace {

TEST(Timing, MedianOfAnOddCountIsTheMiddleValueInAnyOrder) {
  EXPECT_EQ(median({7.0}), 7.0);
  EXPECT_EQ(median({3.0, 1.0, 2.0}), 2.0);
  EXPECT_EQ(median({5.0, 100.0, 4.0, 1.0, 2.0}), 4.0);
}

TEST(Timing, MedianOfAnEvenCountIsTheMeanOfTheTwoMiddleValues) {
  EXPECT_EQ(median({4.0, 1.0}), 2.5);
  EXPECT_EQ(median({10.0, 2.0, 1.0, 4.0}), 3.0);  // not the upper middle (4) nor the lower (2)
}

TEST(Timing, MedianOfNothingIsZero) {
  EXPECT_EQ(median({}), 0.0);
}

TEST(Timing, MsSinceCountsForward) {
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_GE(ms_since(t0), 0.0);
}

}  // namespace
}  // namespace accelviz::unity_test_timing
