#pragma once
// Checks shared by the tests of the K-D tree's and the octree's builds on
// several threads: the same tree as on one thread, and progress and
// cancellation from whichever thread finishes a leaf.
#include <gtest/gtest.h>

#include <atomic>
#include <cstring>
#include <vector>

#include "core/accel/accel.h"
#include "core/geometry/triangle.h"

namespace accelviz::test_scenes {

/// The same tree: node arrays (8-byte nodes, compared as bytes), references and build figures.
template <class Tree>
::testing::AssertionResult same_tree(const Tree& a, const Tree& b) {
  if (a.nodes().size() != b.nodes().size())
    return ::testing::AssertionFailure() << a.nodes().size() << " nodes against " << b.nodes().size();
  for (std::size_t i = 0; i < a.nodes().size(); ++i)
    if (std::memcmp(&a.nodes()[i], &b.nodes()[i], sizeof(a.nodes()[i])) != 0)
      return ::testing::AssertionFailure() << "node " << i << " differs";
  if (a.prim_refs().size() != b.prim_refs().size() ||
      !std::equal(a.prim_refs().begin(), a.prim_refs().end(), b.prim_refs().begin()))
    return ::testing::AssertionFailure() << "the references differ";
  const BuildStats &x = a.build_stats(), &y = b.build_stats();
  // The same sums in the same order: equal to the last bit.
  if (x.sah_cost != y.sah_cost || x.node_count != y.node_count || x.leaf_count != y.leaf_count ||
      x.max_depth != y.max_depth || x.avg_leaf_depth != y.avg_leaf_depth || x.memory_bytes != y.memory_bytes ||
      x.extra.at("references") != y.extra.at("references") || x.extra.at("empty_leaves") != y.extra.at("empty_leaves"))
    return ::testing::AssertionFailure() << "the figures differ: SAH " << x.sah_cost << " against " << y.sah_cost;
  return ::testing::AssertionSuccess();
}

/// A build with `o` (threads above 1, a scene large enough to use them)
/// reports progress in order up to 1, whichever thread reports, and stops
/// at the first refusal: no report after it.
template <class Tree, class Options>
void check_parallel_progress_and_cancellation(const std::vector<Triangle>& s, const Options& o) {
  std::atomic<int> calls{0};
  double last = 0.0;
  const Tree tree(s, o, [&](double f) {
    EXPECT_GE(f, last);
    EXPECT_LE(f, 1.0);
    last = f;
    ++calls;
    return true;
  });
  EXPECT_GT(calls.load(), 5);
  EXPECT_DOUBLE_EQ(last, 1.0);
  std::atomic<int> seen{0};
  EXPECT_THROW(Tree(s, o, [&](double) { return ++seen < 3; }), BuildCancelled);
  EXPECT_EQ(seen.load(), 3);
}

}  // namespace accelviz::test_scenes
