#pragma once
// The one query interface every structure implements (brute force, BVH,
// K-D tree, grid, octree, voxels, two-level, Embree). A virtual call per ray
// (or per batch), never per node: inside, each structure runs a traversal
// templated on whether it collects statistics, so the fast path has no
// counters at all.
#include <cstdint>
#include <exception>
#include <functional>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/geometry/hit.h"
#include "core/geometry/triangle.h"
#include "core/math/ray.h"

namespace accelviz {

/// Per-ray traversal figures, under names common to all structures so that
/// heatmaps compare across them. A structure leaves what it has no notion of at 0.
struct RayStats {
  std::uint32_t nodes_visited = 0;        ///< nodes (or cells) entered
  std::uint32_t box_tests = 0;            ///< ray-box tests performed
  std::uint32_t prim_tests = 0;           ///< ray-primitive tests performed
  std::uint32_t nodes_culled = 0;         ///< children skipped: entry t beyond the closest hit so far
  std::uint32_t nodes_missed = 0;         ///< children whose box the ray missed
  std::uint32_t repeated_prim_tests = 0;  ///< tests of a primitive already tested by this ray
  std::uint32_t empty_cells = 0;          ///< empty cells/voxels stepped (grids)
  std::uint32_t leaves_skipped = 0;       ///< any-hit (BVH): leaves the ray crosses that the early exit never reached
  std::uint32_t instances_visited = 0;    ///< two-level: instances whose BLAS the ray entered (0 for single-level)

  RayStats& operator+=(const RayStats& o) {
    nodes_visited += o.nodes_visited;
    box_tests += o.box_tests;
    prim_tests += o.prim_tests;
    nodes_culled += o.nodes_culled;
    nodes_missed += o.nodes_missed;
    repeated_prim_tests += o.repeated_prim_tests;
    empty_cells += o.empty_cells;
    leaves_skipped += o.leaves_skipped;
    instances_visited += o.instances_visited;
    return *this;
  }
};

/// One event of a traced traversal, for the ray inspector.
struct VisitStep {
  enum class Kind : std::uint8_t {
    node_entered,  ///< box hit and descended into (id = node/cell)
    node_missed,   ///< box tested and missed
    node_culled,   ///< box hit but its entry t lies beyond the closest hit so far
    prim_hit,      ///< primitive test that found a (possibly later superseded) hit (id = primitive)
    prim_miss,     ///< primitive test without a hit
  };
  Kind kind;
  std::uint32_t id;
  float t_entry;  ///< boxes: entry t; primitives: hit t (inf on a miss)
  float t_exit;   ///< boxes: exit t; primitives: unused (inf)
};

struct VisitTrace {
  std::vector<VisitStep> steps;
};

/// Figures every build reports. Structure-specific extras go in `extra`
/// (e.g. "epo", "cells", "empty_cells", "mailbox").
struct BuildStats {
  double build_ms = 0.0;
  std::uint64_t node_count = 0;
  std::uint64_t leaf_count = 0;
  std::uint32_t max_depth = 0;
  double avg_leaf_depth = 0.0;
  std::uint64_t memory_bytes = 0;
  double sah_cost = 0.0;  ///< expected cost per ray under the chosen C_trav/C_isect, normalised by root area
  std::map<std::string, double> extra;
};

/// Progress of a long build: called now and then with the fraction done
/// (0..1). Returning false asks the builder to stop; it then throws
/// BuildCancelled and leaves nothing half-built behind.
using ProgressCallback = std::function<bool(double fraction)>;

struct BuildCancelled : std::exception {
  const char* what() const noexcept override { return "build cancelled"; }
};

/// Query-time choices that do not need a rebuild.
struct QueryOptions {
  TriangleTest triangle_test = TriangleTest::watertight;
  bool ordered = true;  ///< front-to-back child order (false: fixed order, to show what ordering buys)
  /// BVH, with `ordered`: the farther child first (back-to-front), the worst
  /// order, to show what ordering buys. Same hit, more work.
  bool back_to_front = false;
  /// BVH closest hit: "x-ray" counting. No box is culled and no primitive test
  /// is shortened by the closest hit so far, so the counters show the full
  /// traversal as if no hit ended it (the cost hidden behind the first
  /// surface). Same hit. Either flag takes the instrumented path.
  bool xray = false;

  bool operator==(const QueryOptions&) const = default;
};

class Accelerator {
 public:
  virtual ~Accelerator() = default;

  /// Short name as used on the command line ("bvh", "kdtree", "brute", ...).
  virtual std::string name() const = 0;

  /// Closest hit along [ray.tmin, ray.tmax]. `stats` and `trace` may be null;
  /// when both are null the structure runs its counter-free fast path.
  virtual Hit closest_hit(const Ray& ray, const QueryOptions& opts, RayStats* stats = nullptr,
                          VisitTrace* trace = nullptr) const = 0;

  /// True when anything lies in [ray.tmin, ray.tmax]; stops at the first hit found.
  virtual bool any_hit(const Ray& ray, const QueryOptions& opts, RayStats* stats = nullptr) const = 0;

  /// Closest hits of a span of rays: hits[i] = closest_hit(rays[i], opts,
  /// stats.empty() ? nullptr : &stats[i]), the same hits and counters (added
  /// to stats[i] as closest_hit adds them; callers reset them). One virtual
  /// call per span, so a structure whose walk gains from several rays at once
  /// overrides closest_hits_span (Bvh walks counted rays in turns). What
  /// trace_closest, heatmaps and the GUI's heatmap worker call. Throws
  /// std::invalid_argument when hits, or a non-empty stats, differ in size from rays.
  void closest_hits(std::span<const Ray> rays, std::span<Hit> hits, const QueryOptions& opts,
                    std::span<RayStats> stats = {}) const;

  /// Rays per packet of the packet queries.
  static constexpr std::size_t kPacketWidth = 8;

  /// True when the structure walks packets of rays together (Bvh's wide fast
  /// path, Embree's rtcIntersect8/rtcOccluded8); the others answer the
  /// packet queries one ray at a time.
  virtual bool has_packets() const { return false; }

  /// Packet queries, counter-free: rays[8k .. 8k+8) form packet k (the last
  /// may be shorter), walked together where has_packets(). hits[i] is the
  /// closest hit of rays[i], as closest_hit(rays[i], opts) finds it, except
  /// that of two triangles hit at the same t, or within a few ulps of each
  /// other, either may be reported (packets visit leaves in another order,
  /// and which of two such hits wins depends on the order: bvh.md, Traversal,
  /// Packets); occluded[i] = 1 when anything
  /// lies on rays[i]. Options the fast path ignores (back_to_front, xray)
  /// are ignored here too. Packets pay for coherent rays (neighbouring primary
  /// rays) and cost for incoherent ones: bench reports both. Throws
  /// std::invalid_argument when the output differs in size from rays.
  void closest_hits_packets(std::span<const Ray> rays, std::span<Hit> hits, const QueryOptions& opts) const;
  void any_hits_packets(std::span<const Ray> rays, std::span<std::uint8_t> occluded, const QueryOptions& opts) const;

  virtual const BuildStats& build_stats() const = 0;

  /// Whether the structure can be looked into: it fills RayStats per ray
  /// (nodes visited, primitives tested) and its build_stats() count its
  /// nodes, leaves and depth. Every structure of ours can; Embree, the
  /// production reference, keeps its tree and its counters to itself, so its
  /// counter heatmaps are all 0 and its node figures 0, which the views say.
  virtual bool inspectable() const { return true; }

  /// Why this structure cannot trace `ray` ("" when it can): every structure
  /// of ours takes any ray; Embree refuses a few (EmbreeAccelerator). The
  /// queries throw std::invalid_argument with this text on such a ray; a
  /// caller that knows where the rays came from (a ray file) checks first to
  /// name the file and the ray.
  virtual std::string ray_problem(const Ray& /*ray*/) const { return {}; }

 protected:
  /// closest_hits after its size checks; the default calls closest_hit per ray.
  virtual void closest_hits_span(std::span<const Ray> rays, std::span<Hit> hits, const QueryOptions& opts,
                                 std::span<RayStats> stats) const;
  /// The packet queries after their size checks; the defaults answer per ray.
  virtual void closest_packets_span(std::span<const Ray> rays, std::span<Hit> hits, const QueryOptions& opts) const;
  virtual void any_packets_span(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                                const QueryOptions& opts) const;
};

/// The rays of `rays` that `accel` cannot take (Accelerator::ray_problem:
/// Embree's limits), for the callers that leave them out and name the first.
struct RayRefusals {
  std::vector<std::uint8_t> refused;  ///< per ray: 1 when refused (all 0 when none is)
  std::size_t count = 0;
  std::size_t first = 0;  ///< the first refused ray (when count > 0)
  std::string reason;     ///< its ray_problem
};
RayRefusals ray_refusals(const Accelerator& accel, std::span<const Ray> rays);

/// A structure's refusal (an exception's message "embree: ...") without its
/// "NAME: " prefix, for callers that name the structure themselves.
std::string without_name_prefix(std::string message, std::string_view name);

}  // namespace accelviz
