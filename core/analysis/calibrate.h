#pragma once
// Calibrating the SAH constants to this machine: micro-benchmarks of the
// robust ray-box slab test and of both ray-triangle tests over arrays that
// stay in the caches (the tests' cost, not memory's), each the median of
// repeated timed loops. The BVH's SAH
// charges C_trav per inner node visited, and a binary BVH visit tests both
// children's boxes, so C_trav = 2 box tests; normalised to C_trav = 1,
// C_isect = t_triangle / (2 t_box).
#include <cstddef>
#include <cstdint>

namespace accelviz {

struct CalibrateOptions {
  std::size_t items = 1 << 10;    ///< boxes, triangles and rays in each array (rounded up to a power of two)
  std::size_t tests = 1 << 23;    ///< tests per timed loop
  int repeat = 5;                 ///< timed loops per figure; the median is reported
  std::uint64_t seed = 1;         ///< random boxes, triangles and rays
};

struct Calibration {
  double ns_box = 0;                ///< one robust slab test
  double ns_triangle_watertight = 0;  ///< one watertight test (Woop et al. 2013)
  double ns_triangle_fast = 0;      ///< one Möller-Trumbore test
  double box_hit_fraction = 0;      ///< of the random tests: shows the loops did real work
  double triangle_hit_fraction = 0;
  /// SAH constants normalised so C_trav = 1 (one inner node = two box tests).
  double c_isect_watertight() const { return ns_box > 0 ? ns_triangle_watertight / (2 * ns_box) : 0; }
  double c_isect_fast() const { return ns_box > 0 ? ns_triangle_fast / (2 * ns_box) : 0; }
};

/// Runs the micro-benchmarks on the calling thread.
Calibration calibrate(const CalibrateOptions& opts = {});

}  // namespace accelviz
