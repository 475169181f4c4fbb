#include "ui/app/heatmap_worker.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>

#include "core/query/camera.h"
#include "core/scene/effects.h"
#include "core/util/parallel.h"
#include "core/util/timing.h"

namespace accelviz {

void PixelTally::add(const PixelFigures& p) {
  ++rays;
  shadow_rays += p.shadow_rays;
  shadowed += p.shadowed;
  shadow_nodes += p.shadow_nodes;
  shadow_prims += p.shadow_prims;
  if (p.prim != kInvalidId) ++hits;
  sum_nodes += p.nodes;
  sum_prims += p.prims;
  sum_instances += p.instances;
  max_nodes = std::max(max_nodes, p.nodes);
  max_prims = std::max(max_prims, p.prims);
  max_instances = std::max(max_instances, p.instances);
  if (!std::isnan(p.value)) {
    ++valued;
    sum_value += p.value;
    max_value = std::max(max_value, static_cast<double>(p.value));
  }
}

void PixelTally::merge(const PixelTally& o) {
  rays += o.rays;
  hits += o.hits;
  shadow_rays += o.shadow_rays;
  shadowed += o.shadowed;
  shadow_nodes += o.shadow_nodes;
  shadow_prims += o.shadow_prims;
  valued += o.valued;
  sum_nodes += o.sum_nodes;
  sum_prims += o.sum_prims;
  sum_instances += o.sum_instances;
  sum_value += o.sum_value;
  max_value = std::max(max_value, o.max_value);
  max_nodes = std::max(max_nodes, o.max_nodes);
  max_prims = std::max(max_prims, o.max_prims);
  max_instances = std::max(max_instances, o.max_instances);
}

HeatmapSummary PixelTally::summary(double render_ms) const {
  const PixelTally& a = *this;
  HeatmapSummary s;
  s.rays = a.rays;
  s.hits = a.hits;
  if (a.rays > 0) {
    s.mean_nodes = a.sum_nodes / static_cast<double>(a.rays);
    s.mean_prims = a.sum_prims / static_cast<double>(a.rays);
    s.mean_instances = a.sum_instances / static_cast<double>(a.rays);
  }
  s.max_instances = a.max_instances;
  s.max_nodes = a.max_nodes;
  s.max_prims = a.max_prims;
  if (a.valued > 0) s.mean_value = a.sum_value / static_cast<double>(a.valued);
  s.max_value = a.max_value;
  s.render_ms = render_ms;
  s.rays_per_s = render_ms > 0.0 ? static_cast<double>(a.rays) / (render_ms * 1e-3) : 0.0;
  s.shadow_rays = a.shadow_rays;
  s.shadowed = a.shadowed;
  if (a.shadow_rays > 0) {
    s.mean_shadow_nodes = a.shadow_nodes / static_cast<double>(a.shadow_rays);
    s.mean_shadow_prims = a.shadow_prims / static_cast<double>(a.shadow_rays);
  }
  return s;
}

HeatmapSummary summarise_pixels(std::span<const PixelFigures> pixels, double render_ms) {
  // Blocks on all threads, merged in block order: the same figures whatever
  // the threads.
  constexpr std::size_t kBlock = 16384;
  std::vector<PixelTally> blocks((pixels.size() + kBlock - 1) / kBlock);
  parallel_for(blocks.size(), 0, 4, [&](std::size_t b0, std::size_t b1, unsigned) {
    for (std::size_t b = b0; b < b1; ++b)
      for (const PixelFigures& p : pixels.subspan(b * kBlock, std::min(kBlock, pixels.size() - b * kBlock)))
        blocks[b].add(p);
  });
  PixelTally a;
  for (const PixelTally& blk : blocks) a.merge(blk);
  return a.summary(render_ms);
}

namespace {

/// Lattice points of spacing s across n pixels: 0, s, 2s, ...
int lattice_count(int n, int s) {
  return (n + s - 1) / s;
}

/// No one but the pool holds `f`. use_count() reads the count without
/// ordering: the fence orders what this thread then writes to the frame after
/// the last holder's reads of it (its release of the count, which the load read).
bool idle(const std::shared_ptr<HeatmapFrame>& f) {
  if (f.use_count() != 1) return false;
  std::atomic_thread_fence(std::memory_order_acquire);
  return true;
}

}  // namespace

void HeatmapFramePool::release_requests() {
  for (std::shared_ptr<HeatmapFrame>& f : frames_)
    if (idle(f)) f->request = HeatmapRequest{};
}

std::shared_ptr<HeatmapFrame> HeatmapFramePool::take(int stride) {
  release_requests();
  std::shared_ptr<HeatmapFrame> found;
  int same_stride = 0;
  for (std::shared_ptr<HeatmapFrame>& f : frames_) {
    if (f->stride != stride) continue;
    ++same_stride;
    if (!found && idle(f)) found = f;
  }
  if (found) return found;
  auto f = std::make_shared<HeatmapFrame>();
  f->stride = stride;
  if (same_stride < 2) frames_.push_back(f);
  return f;
}

bool trace_progressive(const HeatmapRequest& r, std::uint64_t id, const std::function<bool()>& keep_going,
                       const std::function<void(std::shared_ptr<const HeatmapFrame>)>& publish, HeatmapFramePool* pool,
                       std::atomic<std::uint64_t>* traced) {
  const HeatmapOptions& o = r.options;
  const int w = o.width, h = o.height;
  if (w <= 0 || h <= 0 || !r.structure || !r.structure->accel) return true;
  const Accelerator& accel = *r.structure->accel;
  const unsigned threads = resolve_threads(o.threads);

  int coarsest = 1;
  while (coarsest * 2 <= std::max(1, r.coarsest)) coarsest *= 2;

  // Each level's frame holds its own lattice's figures only (HeatmapFrame::
  // pixels), so no level copies or fills image-sized figures: a level takes
  // the points it shares with the level before from that level's frame
  // (immutable once published) and traces the rest into its own.
  std::shared_ptr<const HeatmapFrame> prev;
  PixelTally total;
  double render_ms = 0.0;
  for (int s = coarsest; s >= 1; s /= 2) {
    const int lw = lattice_count(w, s), lh = lattice_count(h, s);
    std::shared_ptr<HeatmapFrame> frame = pool ? pool->take(s) : std::make_shared<HeatmapFrame>();
    frame->id = id;
    frame->stride = s;
    frame->complete = s == 1;
    frame->request = r;
    MetricImage& image = frame->image;
    image.width = w;
    image.height = h;
    image.metric = o.metric;
    image.values.resize(static_cast<std::size_t>(w) * h);
    HugePageVector<PixelFigures>& pixels = frame->pixels;
    pixels.resize(static_cast<std::size_t>(lw) * lh);

    // Lattice s: rows y = 0, s, 2s, ... Below the coarsest level, the rows
    // of the lattice 2s only need their odd multiples of s; their even ones
    // come from the frame before.
    std::vector<PixelTally> acc(threads);
    std::atomic<bool> stopped{false};
    const auto t0 = std::chrono::steady_clock::now();
    parallel_for(static_cast<std::size_t>(lh), threads, 1, [&](std::size_t b, std::size_t e, unsigned ti) {
      std::vector<Ray> row_rays;
      std::vector<Hit> row_hits;
      std::vector<RayStats> row_stats;
      for (std::size_t ly = b; ly < e; ++ly) {
        if (stopped.load(std::memory_order_relaxed) || !keep_going()) {
          stopped = true;
          return;
        }
        const int y = static_cast<int>(ly) * s;
        PixelFigures* row = pixels.data() + ly * lw;
        const bool done_before = prev && ly % 2 == 0;
        if (done_before) {
          const PixelFigures* from = prev->pixels.data() + (ly / 2) * prev->lattice_width();
          for (int lx = 0; lx < lw; lx += 2) row[lx] = from[lx / 2];
        }
        // The row's pixels in one closest_hits call: a BVH walks them
        // several rays in turns (the counted walk render_metric runs).
        const int lx0 = done_before ? 1 : 0, dlx = done_before ? 2 : 1;
        row_rays.clear();
        for (int lx = lx0; lx < lw; lx += dlx) row_rays.push_back(primary_ray(r.camera, lx * s, y, w, h));
        row_hits.resize(row_rays.size());
        row_stats.assign(row_rays.size(), RayStats{});
        accel.closest_hits(row_rays, row_hits, o.query, row_stats);
        if (traced) traced->fetch_add(row_rays.size(), std::memory_order_relaxed);
        for (std::size_t k = 0; k < row_rays.size(); ++k) {
          const Ray& ray = row_rays[k];
          const Hit& hit = row_hits[k];
          const RayStats& stats = row_stats[k];
          PixelFigures& p = row[lx0 + static_cast<int>(k) * dlx];
          p.value = metric_value(o.metric, ray, hit, stats, o.c_trav, o.c_isect);
          p.nodes = stats.nodes_visited;
          p.prims = stats.prim_tests;
          p.instances = stats.instances_visited;
          p.prim = hit.prim;
          p.t = hit.t;
          p.shadow_rays = p.shadow_nodes = p.shadow_prims = p.shadowed = 0;
          if (hit.valid())
            for (const Light& l : r.shadow_lights) {
              RayStats ss;
              p.shadowed += accel.any_hit(shadow_ray(ray, hit, l), o.query, &ss) ? 1u : 0u;
              ++p.shadow_rays;
              p.shadow_nodes += ss.nodes_visited;
              p.shadow_prims += ss.prim_tests;
            }
          acc[ti].add(p);
        }
        // The image's rows y .. y + s - 1: every lattice point fills its
        // s×s block (the finer levels trace the block's other pixels later);
        // at s = 1 each pixel its own value. The row is made once, then copied.
        float* first = image.values.data() + static_cast<std::size_t>(y) * w;
        for (int x = 0; x < w; ++x) first[x] = row[x / s].value;
        for (int by = y + 1; by < std::min(h, y + s); ++by)
          std::copy(first, first + w, image.values.data() + static_cast<std::size_t>(by) * w);
      }
    });
    render_ms += ms_since(t0);
    if (stopped) return false;
    for (const PixelTally& a : acc) total.merge(a);

    frame->summary = total.summary(render_ms);
    prev = frame;
    publish(std::move(frame));
  }
  return true;
}

HeatmapWorker::HeatmapWorker()
    : worker_([this](const HeatmapRequest& r, std::uint64_t id, const std::function<bool()>& keep_going,
                     const std::function<void(std::shared_ptr<const HeatmapFrame>)>& publish) {
        traced_.store(0, std::memory_order_relaxed);
        job_rays_.store(static_cast<std::uint64_t>(std::max(0, r.options.width)) *
                            static_cast<std::uint64_t>(std::max(0, r.options.height)),
                        std::memory_order_relaxed);
        try {
          trace_progressive(r, id, keep_going, publish, &pool_, &traced_);
        } catch (const std::exception& e) {  // on this thread it would end the program
          std::lock_guard lock(failure_mutex_);
          failure_ = {id, e.what()};
        }
      }) {}

}  // namespace accelviz
