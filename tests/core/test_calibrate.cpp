// Calibration: figures are positive and the implied constants finite (no
// timing thresholds: the figures depend on the machine and its load).
#include <gtest/gtest.h>

#include <cmath>

#include "core/analysis/calibrate.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace accelviz::unity_test_calibrate {
namespace {

TEST(Calibrate, FiguresArePositiveAndRatiosFinite) {
  CalibrateOptions o;
  o.items = 1 << 12;
  o.tests = 1 << 16;
  o.repeat = 3;
  const Calibration c = calibrate(o);
  EXPECT_GT(c.ns_box, 0.0);
  EXPECT_GT(c.ns_triangle_watertight, 0.0);
  EXPECT_GT(c.ns_triangle_fast, 0.0);
  EXPECT_TRUE(std::isfinite(c.c_isect_watertight()));
  EXPECT_TRUE(std::isfinite(c.c_isect_fast()));
  EXPECT_GT(c.c_isect_watertight(), 0.0);
  // The random rays, boxes and triangles mix hits and misses, so neither test is all early-outs.
  EXPECT_GT(c.box_hit_fraction, 0.05);
  EXPECT_LT(c.box_hit_fraction, 0.95);
  EXPECT_GT(c.triangle_hit_fraction, 0.001);
  EXPECT_LT(c.triangle_hit_fraction, 0.95);
  // A size that is not a power of two is rounded up (indices wrap by a mask).
  o.items = 1000;
  const Calibration d = calibrate(o);
  EXPECT_GT(d.ns_box, 0.0);
  EXPECT_GT(d.box_hit_fraction, 0.05);
}

}  // namespace
}  // namespace accelviz::unity_test_calibrate
