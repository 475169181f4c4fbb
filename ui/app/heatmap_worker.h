#pragma once
// The per-pixel metric of the current view, traced on a worker thread and
// refined progressively: first one primary ray per 8×8 block, then the
// pixels of the 4-, 2- and 1-pixel lattices that are still missing (each
// pixel is traced exactly once overall), every level published as soon as
// it is done with each traced value filling its block. A new request (the
// camera moved, the structure or metric changed) cancels the one running,
// so turning the camera stays smooth and the picture sharpens when it stops.
//
// Rays are core's primary_ray(camera, x, y, W, H): pixel centres, row 0 at
// the top, the same convention as `accelviz render` and the GL camera.
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/accel/accel.h"
#include "core/analysis/heatmap.h"
#include "core/util/huge_page_allocator.h"
#include "ui/app/build_worker.h"
#include "ui/app/latest_job_worker.h"

namespace accelviz {

struct HeatmapRequest {
  std::shared_ptr<const BuiltStructure> structure;
  Camera camera;
  /// Metric, size, threads (0: all hardware threads), query options, cost
  /// weights: what the CPU worker and the GPU heatmap trace with. Its
  /// `progress` is not called: the worker cancels through its own keep_going.
  HeatmapOptions options;
  int coarsest = 8;  ///< first lattice spacing (a power of two >= 1)
  /// Shadow rays (effects by scene): from each primary hit, one any-hit ray
  /// per light here (core/scene/effects.h shadow_lights(); empty: none).
  /// Their work is counted apart from the primary ray's (PixelFigures::shadow_*).
  std::vector<Light> shadow_lights;
};

/// What one pixel's ray found (the hover tooltip shows these).
struct PixelFigures {
  float value = 0.0f;                ///< the metric (NaN: no value)
  std::uint32_t nodes = 0;           ///< RayStats::nodes_visited
  std::uint32_t prims = 0;           ///< RayStats::prim_tests
  std::uint32_t instances = 0;       ///< RayStats::instances_visited (two-level; 0 elsewhere)
  std::uint32_t prim = 0xFFFFFFFFu;  ///< hit primitive (kInvalidId: miss)
  float t = 0.0f;                    ///< hit distance (inf: miss)
  std::uint32_t shadow_rays = 0;     ///< any-hit rays traced from the hit toward the lights
  std::uint32_t shadow_nodes = 0;    ///< their RayStats::nodes_visited, summed
  std::uint32_t shadow_prims = 0;    ///< their RayStats::prim_tests, summed
  std::uint32_t shadowed = 0;        ///< of them, rays that found an occluder
};

/// Figures over the pixels traced so far (all of them once complete).
struct HeatmapSummary {
  std::uint64_t rays = 0;
  std::uint64_t hits = 0;
  double mean_nodes = 0.0, mean_prims = 0.0;
  std::uint32_t max_nodes = 0, max_prims = 0;
  double mean_instances = 0.0;  ///< instances visited per pixel (two-level; 0 elsewhere)
  std::uint32_t max_instances = 0;
  double mean_value = 0.0, max_value = 0.0;  ///< of the metric, over pixels with a value
  double render_ms = 0.0;  ///< tracing time of all levels so far (instrumented; the CPU worker's includes writing each
                           ///< level's image rows)
  double rays_per_s = 0.0;
  std::uint64_t shadow_rays = 0;   ///< shadow (any-hit) rays traced (0 when the request has no lights)
  std::uint64_t shadowed = 0;      ///< of them, occluded
  double mean_shadow_nodes = 0.0;  ///< per shadow ray
  double mean_shadow_prims = 0.0;  ///< per shadow ray
};

/// Running totals of pixel figures: add() one pixel, merge() another tally
/// (block tallies merged in block order give the same figures whatever the
/// threads), summary() the HeatmapSummary of all added.
struct PixelTally {
  std::uint64_t rays = 0, hits = 0, valued = 0;
  double sum_nodes = 0.0, sum_prims = 0.0, sum_instances = 0.0, sum_value = 0.0, max_value = 0.0;
  std::uint32_t max_nodes = 0, max_prims = 0, max_instances = 0;
  std::uint64_t shadow_rays = 0, shadowed = 0;
  double shadow_nodes = 0.0, shadow_prims = 0.0;

  void add(const PixelFigures& p);
  void merge(const PixelTally& o);
  HeatmapSummary summary(double render_ms) const;
};

struct HeatmapFrame {
  std::uint64_t id = 0;
  int stride = 1;         ///< lattice spacing of this level (1 = every pixel traced)
  bool complete = false;  ///< stride 1 done
  MetricImage image;      ///< W×H, block-filled below stride 1
  /// The figures of the lattice points (x, y multiples of the stride), row
  /// 0 at the top: lattice_width() × ceil(H / stride); W×H at stride 1.
  /// Read a pixel's through at(), which maps it to its block's point. On
  /// huge pages where the system allows (83 MB at 1920×1080 at stride 1).
  HugePageVector<PixelFigures> pixels;
  HeatmapSummary summary;
  HeatmapRequest request;  ///< what it shows (structure, camera, size, metric)

  int lattice_width() const { return (image.width + stride - 1) / stride; }
  /// The figures pixel (x, y) shows: its own at stride 1, its block's below.
  const PixelFigures& at(int x, int y) const {
    return pixels[static_cast<std::size_t>(y / stride) * lattice_width() + x / stride];
  }
};

/// Frames that no one holds any more, written over by later levels of the
/// same lattice spacing: their pixel and image arrays already have the size
/// (no allocation, no fill, no fresh pages; each level writes every element).
/// At most two per spacing are kept: one shown while the other is written.
/// The CPU worker's levels and GpuHeatmap's frames come from one. Used by one
/// thread at a time.
class HeatmapFramePool {
 public:
  /// A frame for lattice spacing `stride`: an idle kept one, else a new one
  /// (kept when fewer than two of that spacing are). Its fields are stale:
  /// the caller sets every one. Calls release_requests() first.
  std::shared_ptr<HeatmapFrame> take(int stride);
  /// Idle frames let go of their requests (and so of the structures they
  /// name, which may then be freed). Until then a frame let go after the
  /// last take keeps its job's structure alive (the worker's latest frame
  /// does so for the last job in any case).
  void release_requests();
  std::size_t size() const { return frames_.size(); }

 private:
  std::vector<std::shared_ptr<HeatmapFrame>> frames_;
};

/// Traces request `r` level by level, synchronously, calling `publish`
/// after each level (on the calling thread); stops early (returning false)
/// when `keep_going` returns false. `keep_going` is asked once per image
/// row, from all tracing threads at once, so it must be thread-safe. The
/// worker's engine, exposed for tests. With a `pool`, the levels' frames
/// come from it (the worker's jobs reuse the frames of the jobs before).
/// With `traced`, the primary rays traced so far are added to it as rows
/// finish (a job traces width × height rays over all its levels), for the
/// status line's percentage.
bool trace_progressive(const HeatmapRequest& r, std::uint64_t id, const std::function<bool()>& keep_going,
                       const std::function<void(std::shared_ptr<const HeatmapFrame>)>& publish,
                       HeatmapFramePool* pool = nullptr, std::atomic<std::uint64_t>* traced = nullptr);

/// The summary of fully traced pixels (every pixel counted once), as the
/// worker computes it for its frames; used by the GPU path too.
HeatmapSummary summarise_pixels(std::span<const PixelFigures> pixels, double render_ms);

class HeatmapWorker {
 public:
  HeatmapWorker();
  HeatmapWorker(const HeatmapWorker&) = delete;
  HeatmapWorker& operator=(const HeatmapWorker&) = delete;

  /// Replaces whatever is queued or running with `r`; returns its id.
  std::uint64_t request(HeatmapRequest r) { return worker_.request(std::move(r)); }
  /// Stops the running job and drops the queued one.
  void cancel() { worker_.cancel(); }
  /// The newest published level of any job (null before the first).
  std::shared_ptr<const HeatmapFrame> latest() const { return worker_.latest(); }
  /// A job is queued or running.
  bool busy() const { return worker_.busy(); }
  std::uint64_t latest_request() const { return worker_.latest_request(); }
  /// The last job that failed (0: none yet) and why: a structure's query threw (Embree refuses
  /// rays beyond its reach), so that job publishes no further level.
  std::pair<std::uint64_t, std::string> failure() const {
    std::lock_guard lock(failure_mutex_);
    return failure_;
  }
  /// The running job's share of its rays traced, 0 to 1 (a long trace said only "refining").
  double progress() const {
    const std::uint64_t total = job_rays_.load(std::memory_order_relaxed);
    return total > 0 ? std::min(1.0, static_cast<double>(traced_.load(std::memory_order_relaxed)) / total) : 0.0;
  }

 private:
  HeatmapFramePool pool_;  ///< the worker thread's only
  std::atomic<std::uint64_t> traced_{0}, job_rays_{0};  ///< the running job's rays traced, and all of them
  mutable std::mutex failure_mutex_;
  std::pair<std::uint64_t, std::string> failure_{0, ""};
  /// A superseded job's levels are never shown (the default store rule).
  LatestJobWorker<HeatmapRequest, std::shared_ptr<const HeatmapFrame>> worker_;
};

}  // namespace accelviz
