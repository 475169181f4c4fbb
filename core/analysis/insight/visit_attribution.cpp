#include "core/analysis/insight/visit_attribution.h"

#include <algorithm>
#include <atomic>
#include <mutex>
#include <stdexcept>
#include <string>

#include "core/query/ray_sets.h"
#include "core/util/parallel.h"

namespace accelviz {

VisitRecord record_visits(const Accelerator& accel, std::span<const Ray> rays, int width, int height,
                          const QueryOptions& query, unsigned threads, const ProgressCallback& progress) {
  if (width <= 0 || height <= 0 || rays.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height))
    throw std::invalid_argument("record_visits: " + std::to_string(rays.size()) + " rays for a " +
                                std::to_string(width) + "x" + std::to_string(height) + " image");
  const std::size_t n = rays.size();
  std::vector<std::vector<std::uint32_t>> node_rows(n), prim_rows(n);
  VisitRecord rec;
  rec.width = width;
  rec.height = height;
  rec.stats.resize(n);
  rec.hit_prim.assign(n, VisitRecord::kNoHitPrim);
  std::atomic<bool> cancelled{false};
  std::atomic<std::size_t> done{0};
  std::mutex progress_mutex;
  parallel_for(n, resolve_threads(threads), 256, [&](std::size_t begin, std::size_t end, unsigned) {
    if (cancelled.load(std::memory_order_relaxed)) return;
    VisitTrace trace;
    for (std::size_t i = begin; i < end; ++i) {
      trace.steps.clear();
      RayStats st;
      const Hit h = accel.closest_hit(rays[i], query, &st, &trace);
      rec.stats[i] = st;
      if (h.valid()) rec.hit_prim[i] = h.prim;
      for (const VisitStep& s : trace.steps) {
        if (s.kind == VisitStep::Kind::node_entered)
          node_rows[i].push_back(s.id);
        else if (s.kind == VisitStep::Kind::prim_hit || s.kind == VisitStep::Kind::prim_miss)
          prim_rows[i].push_back(s.id);
      }
    }
    const std::size_t d = done.fetch_add(end - begin) + (end - begin);
    if (progress) {
      std::lock_guard lock(progress_mutex);
      if (!progress(static_cast<double>(d) / static_cast<double>(n))) cancelled = true;
    }
  });
  if (cancelled) throw BuildCancelled();
  rec.node_offsets.resize(n + 1);
  rec.prim_offsets.resize(n + 1);
  std::size_t nn = 0, np = 0;
  for (std::size_t i = 0; i < n; ++i) {
    rec.node_offsets[i] = static_cast<std::uint32_t>(nn);
    rec.prim_offsets[i] = static_cast<std::uint32_t>(np);
    nn += node_rows[i].size();
    np += prim_rows[i].size();
  }
  rec.node_offsets[n] = static_cast<std::uint32_t>(nn);
  rec.prim_offsets[n] = static_cast<std::uint32_t>(np);
  rec.nodes.reserve(nn);
  rec.prims.reserve(np);
  for (std::size_t i = 0; i < n; ++i) {
    rec.nodes.insert(rec.nodes.end(), node_rows[i].begin(), node_rows[i].end());
    rec.prims.insert(rec.prims.end(), prim_rows[i].begin(), prim_rows[i].end());
  }
  return rec;
}

VisitRecord record_view_visits(const Accelerator& accel, const Camera& camera, int width, int height,
                               const QueryOptions& query, unsigned threads, const ProgressCallback& progress) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("record_view_visits: image size must be positive");
  const std::vector<Ray> rays = primary_rays(camera, width, height);
  return record_visits(accel, rays, width, height, query, threads, progress);
}

std::vector<std::uint64_t> node_visit_counts(const VisitRecord& rec, std::size_t node_count) {
  std::vector<std::uint64_t> counts(node_count, 0);
  for (const std::uint32_t id : rec.nodes)
    if (id < node_count) ++counts[id];
  return counts;
}

std::vector<HotNode> top_hot_nodes(std::span<const std::uint64_t> counts, std::size_t n) {
  std::vector<HotNode> all;
  for (std::size_t i = 0; i < counts.size(); ++i)
    if (counts[i] > 0) all.push_back({static_cast<std::uint32_t>(i), counts[i]});
  const auto hotter = [](const HotNode& a, const HotNode& b) {
    return a.visits > b.visits || (a.visits == b.visits && a.node < b.node);
  };
  if (all.size() > n) {
    std::partial_sort(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(n), all.end(), hotter);
    all.resize(n);
  } else {
    std::sort(all.begin(), all.end(), hotter);
  }
  return all;
}

std::vector<std::uint8_t> pixels_visiting(const VisitRecord& rec, std::uint32_t node) {
  const std::size_t n = rec.pixel_count();
  std::vector<std::uint8_t> mask(n, 0);
  for (std::size_t p = 0; p < n; ++p)
    for (const std::uint32_t id : rec.nodes_of(p))
      if (id == node) {
        mask[p] = 1;
        break;
      }
  return mask;
}

namespace {
void sort_unique(std::vector<std::uint32_t>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}
}  // namespace

RegionTouch region_touch(const VisitRecord& rec, int x0, int y0, int x1, int y1) {
  RegionTouch r;
  x0 = std::clamp(x0, 0, rec.width);
  x1 = std::clamp(x1, 0, rec.width);
  y0 = std::clamp(y0, 0, rec.height);
  y1 = std::clamp(y1, 0, rec.height);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const std::size_t p =
          static_cast<std::size_t>(y) * static_cast<std::size_t>(rec.width) + static_cast<std::size_t>(x);
      ++r.rays;
      const auto ns = rec.nodes_of(p);
      const auto ps = rec.prims_of(p);
      r.nodes.insert(r.nodes.end(), ns.begin(), ns.end());
      r.prims.insert(r.prims.end(), ps.begin(), ps.end());
      if (rec.hit_prim[p] != VisitRecord::kNoHitPrim) r.hit_prims.push_back(rec.hit_prim[p]);
    }
  sort_unique(r.nodes);
  sort_unique(r.prims);
  sort_unique(r.hit_prims);
  return r;
}

}  // namespace accelviz
