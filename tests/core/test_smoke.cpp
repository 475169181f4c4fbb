#include <gtest/gtest.h>

#include "core/accel/brute_force.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_smoke {

using namespace accelviz;

TEST(BruteForce, FindsNearestOfTwoTriangles) {
  std::vector<Triangle> tris = {
      {{-1, -1, 5}, {1, -1, 5}, {0, 1, 5}},
      {{-1, -1, 3}, {1, -1, 3}, {0, 1, 3}},
  };
  BruteForce bf(tris);
  Hit h = bf.closest_hit(Ray({0, 0, 0}, {0, 0, 1}), {});
  ASSERT_TRUE(h.valid());
  EXPECT_EQ(h.prim, 1u);
  EXPECT_FLOAT_EQ(h.t, 3.0f);
  EXPECT_TRUE(bf.any_hit(Ray({0, 0, 0}, {0, 0, 1}), {}));
  EXPECT_FALSE(bf.any_hit(Ray({0, 0, 0}, {0, 0, -1}), {}));
}
}  // namespace unity_test_smoke
