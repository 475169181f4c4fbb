// Packet traversal of the wide BVH: eight rays walk the tree together (Wald,
// Slusallek, Benthin & Wagner 2001; on wide trees as Embree's rtcIntersect8).
// Included by bvh.cpp right after bvh_wide_traverse.inl, in the same two
// namespaces: once for the 4-wide SSE nodes, once compiled for AVX2 over the
// 8-wide nodes. The includer defines, before the include: kWidth,
// PacketF/PacketI (8-lane GCC vectors of float and int32) and packet_mask
// (bit l = lane l of a comparison result).
// No includes here: the file is pasted inside a namespace.
//
// Each box of a wide node is tested against all eight rays with one set of
// vector operations (ray-parallel: lane l is ray l), instead of each ray
// testing all boxes (box-parallel: the single-ray walk above). A node is
// fetched once for the packet, and the walk's decisions (mask, order, push,
// pop) are made once per node for all its rays. It pays when the rays of a
// packet visit mostly the same nodes: primary rays of neighbouring pixels.
// Incoherent rays (diffuse bounces) visit the union of their paths with
// most lanes idle; bench reports both so the difference can be seen.
//
// The results are the single-ray walk's: each lane's box test is
// intersect_slab's arithmetic on its own ray (near and far planes chosen by
// that ray's direction signs, max/min ignoring NaN in the same operand
// order, the exit padded by the same factor), so a lane enters exactly the
// boxes its ray would enter at the same closest distance; a leaf's triangles
// are tested against all lanes at once with each lane's own arithmetic
// (packet_tri_watertight, packet_tri_mt), or lane by lane with the
// single-ray walk's leaf code (LeafRay). Only the order of the leaves can
// differ (children are ordered by their nearest lane), which can change which
// of two hits at the same t, or a few ulps apart, is reported.

/// Smallest lane (the packet's nearest entry into a box; +inf lanes are idle).
[[gnu::always_inline]] inline float packet_min(const PacketF& v) {
  float m = v[0];
  for (int l = 1; l < 8; ++l) m = v[l] < m ? v[l] : m;
  return m;
}

/// A subtree entered by at most this many lanes is walked by each of them
/// alone (walk_wide), as Embree's hybrid traversal switches to single rays.
/// Diffuse rays in packets, against the same rays one at a time (bunny and
/// dragon, three alternated rounds): never alone 0.84-0.97x, alone at one
/// lane 0.92-1.01x, at up to three or four 0.94-1.05x; primary rays the same
/// for all (docs/performance.md, "Packet queries").
constexpr int kAloneLanes = 4;

/// One triangle against the packet's lanes at once (ray-parallel): the lane
/// tests of bvh_tri4.h (watertight_lanes_edges, watertight_lanes_distance,
/// mt_lanes) with the roles swapped, the triangle's coordinates broadcast
/// and each lane one ray (the watertight test needs all lanes to share the
/// sheared axes kx, ky, kz), so each lane's T, det, t, u, v, candidate and
/// special bits are bit for bit those the ray's own test gives for this
/// triangle. tmax is applied afterwards lane by lane, as the single-ray leaf
/// loop does.
/// Filled at a packet's first leaf (most packets of a scene's primary rays
/// never reach one: zeroing all of it per packet was 7 % of the any-hit walk
/// on the kitchen); lanes without a ray hold ray 0's direction and a zero
/// origin (their results are never read).
struct PacketTriRays {
  bvh_detail::Vec3Lanes<PacketF> o;  ///< watertight: origin[kx], [ky], [kz] per lane
  PacketF sx, sy, sz;                ///< watertight: the shear per lane
  int kx = 0, ky = 1, kz = 2;
  bvh_detail::Vec3Lanes<PacketF> org, dir;  ///< Moller-Trumbore: origin and direction per lane
};
struct PacketTriResult : bvh_detail::LaneFigures<PacketF> {
  int candidate = 0, special = 0;
};

/// Vertex k of lane j of `b`, broadcast (x - 0 keeps every value's bits, -0 included),
/// with its axes in the order a0, a1, a2.
[[gnu::always_inline]] inline void packet_vertex(const bvh_detail::TriBlock4& b, int j, int k, int a0, int a1, int a2,
                                                 bvh_detail::Vec3Lanes<PacketF>& p) {
  const PacketF zero{};
  p.x = b.v[3 * k + a0][j] - zero;
  p.y = b.v[3 * k + a1][j] - zero;
  p.z = b.v[3 * k + a2][j] - zero;
}

/// Block lane j of `b` against the packet: intersect_tri4's operations per ray.
[[gnu::always_inline]] inline void packet_tri_watertight(const bvh_detail::TriBlock4& b, int j, const PacketTriRays& r,
                                                         const PacketF& tmin, PacketTriResult& out) {
  bvh_detail::Vec3Lanes<PacketF> p[3];
  for (int k = 0; k < 3; ++k) packet_vertex(b, j, k, r.kx, r.ky, r.kz, p[k]);
  bvh_detail::WatertightLanes<PacketF> w;
  bvh_detail::watertight_lanes_edges(p[0], p[1], p[2], r.o, r.sx, r.sy, w);
  if (packet_mask(w.ok | w.special) == 0) return bvh_detail::set_lanes(out, 0, 0, 0);  // as intersect_tri4
  bvh_detail::watertight_lanes_distance(r.sz, tmin, w, out);
  bvh_detail::set_lanes(out, packet_mask(w.special), packet_mask(w.late), packet_mask(w.ok));
}

/// Block lane j of `b` against the packet: intersect_tri4_mt's operations per ray.
[[gnu::always_inline]] inline void packet_tri_mt(const bvh_detail::TriBlock4& b, int j, const PacketTriRays& r,
                                                 const PacketF& tmin, PacketTriResult& out) {
  bvh_detail::Vec3Lanes<PacketF> p[3];
  for (int k = 0; k < 3; ++k) packet_vertex(b, j, k, 0, 1, 2, p[k]);
  PacketI ok;
  bvh_detail::mt_lanes(p[0], p[1], p[2], r.org, r.dir, tmin, out, ok);
  out.candidate = packet_mask(ok);
  out.special = 0;
}

/// Walks rays[0 .. count) (count 1..8) through the W-wide copy together and
/// writes each ray's result to out[l]: the hit the single-ray walk
/// (traverse_wide<Ordered, Test>, or occluded_wide<Test> for any hit) finds
/// (best.prim a leaf position).
///  - Ordered (closest hit): a node's hit children are visited nearest first
///    by their packet's smallest entry distance; the others are pushed with
///    each lane's entry distance, and on pop a lane whose entry lies beyond
///    its closest hit drops out (the node is skipped when none is left).
///  - Any hit: the single-ray walk's order, the last hit slot first
///    (sorting by the nearest lane was slower on the bunny's any hits,
///    0.85-0.86x instead of 0.90-0.94x of Embree on diffuse and shadow
///    rays); a lane that finds a hit drops out (its box tests always miss
///    from then on), the walk ends when all lanes have.
template <bool AnyHit, bool Ordered, TriangleTest Test>
void traverse_packet(const bvh_detail::WideBvhT<kWidth>& wide_bvh, const BvhView& bvh, const Ray* rays, int count,
                     Hit* out) {
  using WideNode = bvh_detail::WideNodeT<kWidth>;
  constexpr float kInf = std::numeric_limits<float>::infinity();
  const WideNode* wide = wide_bvh.nodes.data();
  // Lane l: ray l. Unused lanes (count < 8) get an empty interval
  // [+inf, -inf], so no box test ever hits in them.
  const PacketF zero{}, inf = kInf - zero, minus_inf = -kInf - zero;
  PacketF org[3], dir[3], inv[3], tmin = inf, closest = minus_inf;
  PacketI neg[3];
  LeafRay<Test> leaf[8];
  Hit* const best = out;  // each lane's hit so far, kept in place
  if (count == 8) {
    // A full packet is loaded in registers (load_packet, defined by the
    // includer): writing lanes one by one into memory and loading them as
    // vectors stalled on store forwarding (about 12 % of the kitchen's
    // any-hit packet walk).
    load_packet(rays, org, dir, inv, tmin, closest);
  } else {
    // Lanes without a ray: a zero origin and inv_dir, ray 0's direction
    // (their results are never read).
    for (int a = 0; a < 3; ++a) {
      org[a] = zero;
      inv[a] = zero;
      dir[a] = rays[0].direction[a] - zero;
    }
    for (int l = 0; l < count; ++l) {
      const Ray& r = rays[l];
      for (int a = 0; a < 3; ++a) {
        org[a][l] = r.origin[a];
        dir[a][l] = r.direction[a];
        inv[a][l] = r.inv_dir[a];
      }
      tmin[l] = r.tmin;
      closest[l] = r.tmax;
    }
  }
  for (int a = 0; a < 3; ++a) neg[a] = inv[a] < 0.0f;  // as intersect_slab: hi is the near plane
  for (int l = 0; l < count; ++l) {
    best[l] = Hit{};
    leaf[l].reset(rays[l]);
  }
  // Coherent packets (primary rays of neighbouring pixels) have the same
  // direction signs in every lane: then each axis's near and far rows of the
  // node are the same for all lanes, as in the single-ray test, and the
  // per-lane plane selection is skipped.
  const int live = (1 << count) - 1;
  bool uniform = true;
  int near_row[3], far_row[3];
  for (int a = 0; a < 3; ++a) {
    // One mask per axis (a loop over the lanes was 8.6 % of the instructions
    // of the kitchen's primary any-hit packets): every live lane negative,
    // or none.
    const int negative = packet_mask(neg[a]) & live;
    uniform = uniform && (negative == 0 || negative == live);
    const bool first_neg = (negative & 1) != 0;
    near_row[a] = first_neg ? 3 + a : a;
    far_row[a] = first_neg ? a : 3 + a;
  }
  const PacketI lane_bit = {1, 2, 4, 8, 16, 32, 64, 128};
  PacketTriRays tri;  // the ray-parallel triangle test's constants, set at the first leaf
  int tri_mode = -1;  // -1: not yet set up; 1: ray-parallel leaves; 0: lane by lane

  int done = 0;  // any hit: lanes that found one

  struct alignas(32) Entry {
    PacketF t_entry;  ///< per lane; +inf where the lane missed the box
    std::uint32_t child, meta;
    int lanes;  ///< lanes that hit the box
  };
  Entry stack[(kWidth - 1) * kBvhMaxDepth + 1];
  unsigned sp = 0;
  std::uint32_t child = 0, meta = 0;  // the wide root
  int lanes = live;                   // lanes that enter the current node
  for (;;) {
    if (meta == 0 && std::popcount(static_cast<unsigned>(lanes)) <= kAloneLanes) {
      // Few lanes left in this subtree (incoherent rays part early): each
      // walks it alone, single-ray style, instead of dragging idle lanes.
      for (int ls = lanes; ls != 0; ls &= ls - 1) {
        const int l = std::countr_zero(static_cast<unsigned>(ls));
        float c = closest[l];
        if (walk_wide<AnyHit, Ordered, Test>(wide_bvh, bvh, rays[l], leaf[l], child, meta, c, best[l])) {
          done |= 1 << l;
          closest[l] = -kInf;
        } else if constexpr (!AnyHit) {
          closest[l] = c;
        }
      }
      if (AnyHit && done == live) break;
    } else if (meta == 0) {
      const WideNode& n = wide[child];
      // Lanes not entering this node get an empty interval, as unused lanes.
      const PacketF tmax = (PacketI{} + lanes) & lane_bit ? closest : minus_inf;
      int slot[kWidth], hit_lanes[kWidth], k = 0;
      PacketF te[kWidth];
      float key[kWidth];
      for (int s = 0; s < kWidth; ++s) {
        if (n.meta[s] == bvh_detail::kWideEmpty) continue;
        PacketF t0 = tmin, t1 = tmax;
        for (int a = 0; a < 3; ++a) {
          // x - (+0) is x for every float (-0 and NaN too): an exact broadcast.
          PacketF near_plane, far_plane;
          if (uniform) {
            near_plane = n.bounds[near_row[a]][s] - zero;
            far_plane = n.bounds[far_row[a]][s] - zero;
          } else {
            const PacketF lo = n.bounds[a][s] - zero, hi = n.bounds[3 + a][s] - zero;
            near_plane = neg[a] ? hi : lo;
            far_plane = neg[a] ? lo : hi;
          }
          const PacketF tn = (near_plane - org[a]) * inv[a];
          const PacketF tf = ((far_plane - org[a]) * inv[a]) * kSlabExitScale;
          t0 = tn > t0 ? tn : t0;  // maxps(tn, t0): NaN keeps t0
          t1 = tf < t1 ? tf : t1;  // minps(tf, t1): NaN keeps t1
        }
        const PacketI hit = t0 <= t1;
        const int m = packet_mask(hit) & lanes;
        if (m == 0) continue;
        slot[k] = s;
        hit_lanes[k] = m;
        te[k] = hit ? t0 : inf;
        if constexpr (Ordered && !AnyHit) key[k] = packet_min(te[k]);
        ++k;
      }
      if (k != 0) {
        int order[kWidth];
        if constexpr (Ordered && !AnyHit) {
          // By the packet's nearest entry, ties in slot order, as the
          // single-ray walk orders its slots (bvh_wide.h).
          if (k == 1)
            order[0] = 0;
          else if (k == 2)
            bvh_detail::order_two_hit_slots(0b11, key, order[0], order[1]);
          else
            bvh_detail::sort_hit_slots<kWidth>((1 << k) - 1, key, order);
        } else {
          for (int i = 0; i < k; ++i) order[i] = AnyHit ? k - 1 - i : i;  // any hit: last slot first
        }
        for (int j = k - 1; j >= 1; --j) {
          const int i = order[j];
          const std::uint32_t c = n.child[slot[i]], m = n.meta[slot[i]];
          prefetch_slot(wide, bvh, c, m);
          stack[sp++] = {te[i], c, m, hit_lanes[i]};
        }
        child = n.child[slot[order[0]]];
        meta = n.meta[slot[order[0]]];
        lanes = hit_lanes[order[0]];
        continue;
      }
    } else {
      if (tri_mode < 0) {
        // First leaf of this packet: set up the ray-parallel triangle test
        // (for the watertight test only when every lane's set-up shears the
        // same axes), for all lanes at once.
        tri_mode = 1;
        if constexpr (Test == TriangleTest::watertight) {
          // WatertightRay's selections lane by lane (the same comparisons
          // on the same values, so the same axes), then its three divisions
          // once for all lanes (IEEE divisions: each lane's quotient is the
          // scalar one).
          const PacketF ax = (PacketF)((PacketI)dir[0] & 0x7FFFFFFF), ay = (PacketF)((PacketI)dir[1] & 0x7FFFFFFF),
                        az = (PacketF)((PacketI)dir[2] & 0x7FFFFFFF);  // std::fabs: the bits
          PacketI z;
          watertight_z_axis(ax, ay, az, z);
          const int kz = z[0];
          const PacketF dz = dir[kz];
          const int negative = packet_mask(dz < 0.0f) & live;
          if ((packet_mask(z == kz) & live) != live || (negative != 0 && negative != live)) {
            tri_mode = 0;  // lanes shear different axes: each tests alone
          } else {
            const int x = watertight_x_axis(kz), y = watertight_y_axis(kz);
            tri.kz = kz;
            tri.kx = negative != 0 ? y : x;  // keep the winding: swap x and y when dir[kz] < 0
            tri.ky = negative != 0 ? x : y;
            tri.sx = dir[tri.kx] / dz;
            tri.sy = dir[tri.ky] / dz;
            tri.sz = 1.0f / dz;
            tri.o = {org[tri.kx], org[tri.ky], org[tri.kz]};
          }
        } else {
          tri.org = {org[0], org[1], org[2]};
          tri.dir = {dir[0], dir[1], dir[2]};
        }
      }
      if (tri_mode == 1 && std::popcount(static_cast<unsigned>(lanes)) > 1) {
        // Each triangle once for all lanes; per lane the single-ray leaf
        // loop's order (blocks, then lanes of a block) and acceptance.
        int act = lanes;
        const bvh_detail::TriBlock4* const end = bvh.blocks + child + meta;
        for (const bvh_detail::TriBlock4* blk = bvh.blocks + child; blk != end && act != 0; ++blk) {
          const int valid = bvh_detail::tri4_used_lanes(*blk);
          for (int j = 0; j < 4 && act != 0; ++j) {
            if (((valid >> j) & 1) == 0) continue;
            PacketTriResult res;
            if constexpr (Test == TriangleTest::watertight)
              packet_tri_watertight(*blk, j, tri, tmin, res);
            else
              packet_tri_mt(*blk, j, tri, tmin, res);
            int ls = (res.candidate | res.special) & act;
            if (ls == 0) continue;
            const Triangle t3 = bvh_detail::tri4_triangle(*blk, static_cast<std::uint32_t>(j));
            for (; ls != 0; ls &= ls - 1) {
              const int l = std::countr_zero(static_cast<unsigned>(ls));
              const float cl = closest[l];
              // The hit's fields go to best[l] one by one: assembling a Hit
              // and copying it read back its just-written floats as one
              // 16-byte load (a store-forwarding stall, 7 % of the any-hit
              // walk on the kitchen).
              float ht, hu, hv;
              bool hit;
              if ((res.special >> l) & 1) {
                leaf[l].prepare();
                Hit h;
                hit = intersect_watertight(rays[l], leaf[l].wr_.v.wr, t3, tmin[l], cl, h);
                ht = h.t;
                hu = h.u;
                hv = h.v;
              } else {
                if constexpr (Test == TriangleTest::watertight)
                  hit = bvh_detail::watertight_accept_tmax(res.det[l], res.T[l], res.t[l], cl);
                else
                  hit = res.t[l] <= cl;  // Moller-Trumbore's last check
                ht = res.t[l];
                hu = res.u[l];
                hv = res.v[l];
              }
              if (!hit) continue;
              if constexpr (AnyHit) {
                best[l].t = ht;
                best[l].u = hu;
                best[l].v = hv;
                best[l].prim = blk->pos[j];
                done |= 1 << l;
                closest[l] = -kInf;
                act &= ~(1 << l);
              } else if (ht < best[l].t) {
                best[l].t = ht;
                best[l].u = hu;
                best[l].v = hv;
                best[l].prim = blk->pos[j];
                best[l].ng = triangle_normal(t3);
                closest[l] = ht;
              }
            }
          }
        }
      } else
        for (int ls = lanes; ls != 0; ls &= ls - 1) {
          const int l = std::countr_zero(static_cast<unsigned>(ls));
          float c = closest[l];
          if (leaf[l].template test<AnyHit>(bvh, child, meta, tmin[l], c, best[l])) {
            done |= 1 << l;
            closest[l] = -kInf;  // its box tests miss from now on
          } else if constexpr (!AnyHit) {
            closest[l] = c;
          }
        }
      if (AnyHit && done == live) break;
    }
    bool more = false;
    while (sp != 0) {
      const Entry& e = stack[--sp];
      const int m = e.lanes & packet_mask(e.t_entry <= closest);
      if (m == 0) continue;  // every lane's entry lies beyond its closest hit (or it is done)
      child = e.child;
      meta = e.meta;
      lanes = m;
      more = true;
      break;
    }
    if (!more) break;
  }
}

/// traverse_packet over a span, in packets of eight consecutive rays (the
/// last one shorter).
template <bool AnyHit, bool Ordered, TriangleTest Test>
void traverse_packets(const bvh_detail::WideBvhT<kWidth>& wide_bvh, const BvhView& bvh, std::span<const Ray> rays,
                      Hit* out) {
  for (std::size_t b = 0; b < rays.size(); b += 8) {
    const int count = static_cast<int>(std::min<std::size_t>(8, rays.size() - b));
    traverse_packet<AnyHit, Ordered, Test>(wide_bvh, bvh, rays.data() + b, count, out + b);
  }
}
