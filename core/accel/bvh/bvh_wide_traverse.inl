// The fast-path traversal of the wide BVH, included twice by bvh.cpp: once
// for the 4-wide SSE nodes and once, compiled for AVX2, for the 8-wide nodes.
// The includer defines, in the enclosing namespace: kWidth (4 or 8),
// WideSlabRayW and wide_slab_test_w (the box test of that width).
// No includes here: the file is pasted inside a namespace.

/// One ray's side of a leaf: its triangle-test constants (set up at its
/// first leaf: many rays never reach one) and the loop over a leaf slot's
/// triangle blocks. The single-ray walk below has one; the packet walk
/// (bvh_packet_traverse.inl) one per lane, so both test a leaf's triangles
/// with the same code, in the same order, with the same results.
template <TriangleTest Test>
struct LeafRay {
  const Ray* ray;
  bool ready;  ///< the constants below are set up for *ray
  // Unset until prepare(): their default member initialisers were stores on
  // every query and every packet lane (4.7 % of the instructions of the
  // kitchen's primary any-hit packets).
  bvh_detail::Unset<InlineWatertightRay> wr_;
#ifdef ACCELVIZ_BVH_TRI4_SSE2
  bvh_detail::Unset<bvh_detail::Tri4Ray> tr4_;
  bvh_detail::Unset<bvh_detail::Tri4MtRay> tm4_;
#endif

  LeafRay() = default;  ///< unset; reset() before use
  /// A single ray: Moller-Trumbore's constants right away (cheap; the
  /// bunny's single-ray any hits in the fast mode measured a few per cent
  /// slower, two rounds, when they waited for the first leaf), the
  /// watertight ones at the first leaf.
  [[gnu::always_inline]] explicit LeafRay(const Ray& r) {
    reset(r);
    if constexpr (Test == TriangleTest::moller_trumbore) prepare();
  }

  /// Starts over for ray `r` (the packet walk reuses its lanes in place).
  [[gnu::always_inline]] void reset(const Ray& r) {
    ray = &r;
    ready = false;
  }

  /// Sets the triangle test's constants up (once per ray).
  [[gnu::always_inline]] void prepare() {
    if (ready) return;
    ready = true;
    if constexpr (Test == TriangleTest::watertight) {
      wr_.v = InlineWatertightRay(*ray);
#ifdef ACCELVIZ_BVH_TRI4_SSE2
      tr4_.v = bvh_detail::Tri4Ray(wr_.v);
#endif
    } else {
#ifdef ACCELVIZ_BVH_TRI4_SSE2
      tm4_.v = bvh_detail::Tri4MtRay(*ray);
#endif
    }
  }

  /// Tests leaf slot (first block `child`, `meta` blocks) in lane order.
  /// Closest hit: keeps the first found at the smallest t in best (with its
  /// normal) and lowers `closest`; returns false. Any hit: returns true at
  /// the first hit (in best). best.prim is the leaf position.
  template <bool AnyHit>
  [[gnu::always_inline]] bool test(const BvhView& bvh, std::uint32_t child, std::uint32_t meta, float tmin,
                                   float& closest, Hit& best) {
    const Ray& r = *ray;
    prepare();
    const bvh_detail::TriBlock4* const end = bvh.blocks + child + meta;
#ifdef ACCELVIZ_BVH_TRI4_SSE2
    if constexpr (Test == TriangleTest::watertight) {
      // Watertight leaves, four triangles per test (bvh_tri4.h). Lanes in
      // slot order are the leaf's triangles in order: the same sequence of
      // tests and acceptances as the scalar loop below.
      for (const bvh_detail::TriBlock4* blk = bvh.blocks + child; blk != end; ++blk) {
#ifdef ACCELVIZ_BVH_WIDE8_AVX2
        if constexpr (kWidth == 8)
          if (end - blk >= 2) {  // two blocks in one test (bvh_tri8.h)
            bvh_detail::Tri8Result res;
            bvh_detail::intersect_tri8(blk, wr_.v, tmin, res);
            const int lanes = (res.candidate | res.special) & bvh_detail::tri8_used_lanes(blk);
            if (accept_watertight<AnyHit>(blk, res, lanes, tmin, closest, best)) return true;
            ++blk;  // and the loop's
            continue;
          }
#endif
        bvh_detail::Tri4Result res;
        bvh_detail::intersect_tri4(*blk, tr4_.v, tmin, res);
        const int lanes = (res.candidate | res.special) & bvh_detail::tri4_used_lanes(*blk);
        if (accept_watertight<AnyHit>(blk, res, lanes, tmin, closest, best)) return true;
      }
      return false;
    } else if constexpr (Test == TriangleTest::moller_trumbore) {
      // Moller-Trumbore leaves, four triangles per test: lanes in order, each
      // accepted against the closest hit so far, as the scalar loop below
      // would (t <= tmax is the scalar test's last check).
      for (const bvh_detail::TriBlock4* blk = bvh.blocks + child; blk != end; ++blk) {
#ifdef ACCELVIZ_BVH_WIDE8_AVX2
        if constexpr (kWidth == 8)
          if (end - blk >= 2) {  // two blocks in one test (bvh_tri8.h)
            bvh_detail::Tri8MtResult res;
            bvh_detail::intersect_tri8_mt(blk, *ray, tmin, res);
            if (accept_mt<AnyHit>(blk, res, res.candidate & bvh_detail::tri8_used_lanes(blk), closest, best))
              return true;
            ++blk;  // and the loop's
            continue;
          }
#endif
        bvh_detail::Tri4MtResult res;
        bvh_detail::intersect_tri4_mt(*blk, tm4_.v, tmin, res);
        if (accept_mt<AnyHit>(blk, res, res.candidate & bvh_detail::tri4_used_lanes(*blk), closest, best)) return true;
      }
      return false;
    } else
#endif
    {
      // A wide leaf slot names its first block and its block count; the
      // leaf's triangles are its blocks' used lanes in order.
      for (const bvh_detail::TriBlock4* blk = bvh.blocks + child; blk != end; ++blk)
        for (int l = 0; l < 4; ++l) {
          if (blk->pos[l] == bvh_detail::kTri4Empty) continue;
          Hit h;
          if (test_triangle<Test>(r, wr_.v, bvh_detail::tri4_triangle(*blk, static_cast<std::uint32_t>(l)), tmin,
                                  closest, h) &&
              take_hit<AnyHit>(*blk, l, h.t, h.u, h.v, closest, best))
            return true;
        }
      return false;
    }
  }

#ifdef ACCELVIZ_BVH_TRI4_SSE2
  /// The lanes `lanes` of an N-lane watertight result over blocks
  /// blk[0 .. N/4), in lane order (the leaf's order): a special lane
  /// answered by the scalar test, the others accepted against the closest
  /// hit so far (the scalar test's last, tmax-dependent step), each hit
  /// taken as the scalar loop over the leaf would. True: an any hit.
  template <bool AnyHit, int N>
  [[gnu::always_inline]] bool accept_watertight(const bvh_detail::TriBlock4* blk,
                                                const bvh_detail::TriLanesResult<N>& res, int lanes, float tmin,
                                                float& closest, Hit& best) {
    while (lanes != 0) {
      const int l = std::countr_zero(static_cast<unsigned>(lanes));
      lanes &= lanes - 1;
      const bvh_detail::TriBlock4& b = blk[N == 4 ? 0 : l >> 2];
      float t, u, v;
      bool hit;
      if ((res.special >> l) & 1) {
        Hit h;
        hit = intersect_watertight(*ray, wr_.v.wr, bvh_detail::tri4_triangle(b, static_cast<std::uint32_t>(l & 3)),
                                   tmin, closest, h);
        t = h.t;
        u = h.u;
        v = h.v;
      } else {
        hit = bvh_detail::watertight_accept_tmax(res.det[l], res.T[l], res.t[l], closest);
        t = res.t[l];
        u = res.u[l];
        v = res.v[l];
      }
      if (hit && take_hit<AnyHit>(b, l & 3, t, u, v, closest, best)) return true;
    }
    return false;
  }

  /// The lanes `lanes` of an N-lane Moller-Trumbore result, in lane order,
  /// each a hit when t <= the closest hit so far (the scalar test's last check).
  template <bool AnyHit, int N>
  [[gnu::always_inline]] bool accept_mt(const bvh_detail::TriBlock4* blk, const bvh_detail::TriLanesMtResult<N>& res,
                                        int lanes, float& closest, Hit& best) {
    while (lanes != 0) {
      const int l = std::countr_zero(static_cast<unsigned>(lanes));
      lanes &= lanes - 1;
      const float t = res.t[l];
      if (!(t <= closest)) continue;
      if (take_hit<AnyHit>(blk[N == 4 ? 0 : l >> 2], l & 3, t, res.u[l], res.v[l], closest, best)) return true;
    }
    return false;
  }
#endif
};

/// Starts fetching what slot (c, m) leads to: a wide node (four cache lines)
/// or a leaf slot's triangle blocks (the first 256 bytes: one block of 160
/// and the start of a merged slot's second). The walks call it for every
/// child they will visit, the one they go to next included (as Embree's
/// walk does): that child's loads then overlap the rest of this step (the
/// next node's child line is otherwise read only after its box test, a
/// leaf's blocks after the leaf test's set-up).
template <class WideNode>
[[gnu::always_inline]] inline void prefetch_slot(const WideNode* wide, const BvhView& bvh, std::uint32_t c,
                                                 std::uint32_t m) {
  const char* p = m == 0 ? reinterpret_cast<const char*>(wide + c) : reinterpret_cast<const char*>(bvh.blocks + c);
  __builtin_prefetch(p);
  __builtin_prefetch(p + 64);
  __builtin_prefetch(p + 128);
  __builtin_prefetch(p + 192);
}

/// Fast-path traversal of the W-wide copy (no statistics). Same contract as
/// traverse<AnyHit, Ordered, false, Test>: hits on the same triangles, ties
/// kept by "first found at the smallest t".
///  - Ordered: hit children sorted by entry distance, nearest taken, the
///    others pushed farthest first; on pop a child whose entry lies beyond
///    the closest hit is skipped.
///  - Unordered: slot order.
///  - Any hit (either mode): the last hit slot first, then the others from
///    the last down (Embree's any-hit order).
/// Stack: at most W - 1 entries per wide level, and a wide path is no longer
/// than the binary one (kBvhMaxDepth).
///
/// walk_wide is that walk from slot (child, meta) on (0, 0: the root), with
/// the closest hit so far in closest/best (its leaf tests by `leaf`): what
/// traverse_wide runs from the root, and the packet walk for a lane that
/// goes on alone. Returns true when an any-hit walk found a hit.
template <bool AnyHit, bool Ordered, TriangleTest Test>
[[gnu::always_inline]] inline bool walk_wide(const bvh_detail::WideBvhT<kWidth>& wide_bvh, const BvhView& bvh,
                                             const Ray& ray, LeafRay<Test>& leaf, std::uint32_t child,
                                             std::uint32_t meta, float& closest, Hit& best) {
  using WideNode = bvh_detail::WideNodeT<kWidth>;
  const WideNode* wide = wide_bvh.nodes.data();
  const WideSlabRayW wrw(ray);
  const float tmin = ray.tmin;

  // Closest hit keeps each pushed child's entry distance (a pop beyond the
  // closest hit is skipped); any hit ends at its first hit and needs none.
  struct ClosestEntry {
    std::uint32_t child, meta;
    float t_entry;
  };
  struct AnyEntry {
    std::uint32_t child, meta;
  };
  using Entry = std::conditional_t<AnyHit, AnyEntry, ClosestEntry>;
  Entry stack[(kWidth - 1) * kBvhMaxDepth + 1];
  unsigned sp = 0;
  for (;;) {
    if (meta == 0) {
      const WideNode& n = wide[child];
      alignas(32) float te[kWidth];
      int mask = wide_slab_test_w(n, wrw, tmin, closest, te);
      if (mask != 0) {
        if ((mask & (mask - 1)) == 0) {  // one child: no ordering, no push
          const int s = std::countr_zero(static_cast<unsigned>(mask));
          child = n.child[s];
          meta = n.meta[s];
          prefetch_slot(wide, bvh, child, meta);
          continue;
        }
        if constexpr (AnyHit) {
          // Any hit: any occluder ends the walk; no sort (it bought little
          // and cost a data-dependent shuffle per node), the last hit slot
          // first, as Embree's any-hit walk: measured better than slot order
          // on shadow and primary rays from two opposite cameras
          // (docs/performance.md, "Any hit: last slot first"). So the lower
          // slots are pushed lowest first (popped highest first) in one
          // pass, and the walk goes on to the last.
          const int last = 31 - std::countl_zero(static_cast<unsigned>(mask));
          for (mask &= ~(1 << last); mask != 0; mask &= mask - 1) {
            const int s = std::countr_zero(static_cast<unsigned>(mask));
            prefetch_slot(wide, bvh, n.child[s], n.meta[s]);
            stack[sp++] = {n.child[s], n.meta[s]};
          }
          child = n.child[last];
          meta = n.meta[last];
          prefetch_slot(wide, bvh, child, meta);
          continue;
        } else {
          int slot[kWidth], k = 0;
          if constexpr (Ordered) {
            // Nearest first, without branching on the distances
            // (bvh_wide.h). Two children, the commonest case: the far one
            // pushed, on to the near one.
            const unsigned rest = static_cast<unsigned>(mask & (mask - 1));  // not 0: two or more hit
            if ((rest & (rest - 1)) == 0) {
              int near, far;
              bvh_detail::order_two_hit_slots(mask, te, near, far);
              const std::uint32_t c = n.child[far], m = n.meta[far];
              prefetch_slot(wide, bvh, c, m);
              stack[sp++] = {c, m, te[far]};
              child = n.child[near];
              meta = n.meta[near];
              prefetch_slot(wide, bvh, child, meta);
              continue;
            }
            k = bvh_detail::sort_hit_slots<kWidth>(mask, te, slot);
          } else {
            while (mask != 0) {
              slot[k++] = std::countr_zero(static_cast<unsigned>(mask));
              mask &= mask - 1;
            }
          }
          // The pushed children are visited later: start fetching them now, so
          // that deep walks through large trees overlap the memory latency.
          for (int j = k - 1; j >= 1; --j) {
            const std::uint32_t c = n.child[slot[j]], m = n.meta[slot[j]];
            prefetch_slot(wide, bvh, c, m);
            stack[sp++] = {c, m, te[slot[j]]};
          }
          child = n.child[slot[0]];
          meta = n.meta[slot[0]];
          prefetch_slot(wide, bvh, child, meta);
          continue;
        }
      }
    } else if (leaf.template test<AnyHit>(bvh, child, meta, tmin, closest, best)) {
      return true;
    }
    for (;;) {
      if (sp == 0) return false;
      const Entry e = stack[--sp];
      if constexpr (!AnyHit)
        if (e.t_entry > closest) continue;
      child = e.child;
      meta = e.meta;
      break;
    }
  }
}

/// Bvh::closest_hit's single-ray walk from the root.
template <bool Ordered, TriangleTest Test>
Hit traverse_wide(const bvh_detail::WideBvhT<kWidth>& wide_bvh, const BvhView& bvh, const Ray& ray) {
  Hit best;
  float closest = ray.tmax;
  LeafRay<Test> leaf(ray);
  walk_wide<false, Ordered, Test>(wide_bvh, bvh, ray, leaf, 0, 0, closest, best);
  return best;
}

/// Bvh::any_hit's single-ray walk from the root (any hit ignores the
/// ordering): whether a hit exists, with the leaf test's stores into a local
/// that nothing reads and a bool returned in a register.
template <TriangleTest Test>
bool occluded_wide(const bvh_detail::WideBvhT<kWidth>& wide_bvh, const BvhView& bvh, const Ray& ray) {
  Hit best;
  float closest = ray.tmax;
  LeafRay<Test> leaf(ray);
  return walk_wide<true, false, Test>(wide_bvh, bvh, ray, leaf, 0, 0, closest, best);
}
