#pragma once
// The heatmap's primary rays traced on the GPU: shaders/trace_bvh.comp, one
// compute invocation per pixel over the binary BVH's flat node array and its
// leaf-ordered triangles (two std430 storage buffers), counting what the
// CPU's instrumented BVH traversal counts. Needs a current GL 4.5 context
// (OsMesaContext headless, the GUI's window context); every call must come
// from the thread that context is current on.
//
// The per-pixel figures are read in place (read_pixels) and turned into
// core's RayStats and Hit per pixel (stats_of, hit_of), so the heatmap's
// metric values, colour map, legend and PNG writing are core's
// (metric_value, colorize, write_png): only the tracing moves.
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "core/accel/accel.h"
#include "core/accel/bvh/bvh.h"
#include "core/analysis/heatmap.h"
#include "core/scene/scene.h"
#include "ui/gl/gl_object.h"
#include "ui/gl/shader.h"

namespace accelviz {

/// One pixel as the shader writes it (shaders/trace_bvh.comp PixelOut, eight
/// 32-bit words): the five counters, the hit triangle in the BVH's leaf
/// order (kInvalidId on a miss) and the hit distance. Read in place through
/// GpuBvhTracer::read_pixels; stats_of and hit_of give core's forms.
struct GpuPixel {
  std::uint32_t nodes_visited;
  std::uint32_t box_tests;
  std::uint32_t prim_tests;
  std::uint32_t nodes_culled;
  std::uint32_t nodes_missed;
  std::uint32_t prim;
  float t;
  std::uint32_t pad;
};
static_assert(sizeof(GpuPixel) == 32);

/// What one GPU trace returns: per pixel, row-major from the top row, the
/// same figures `Bvh::closest_hit(ray, query, &stats)` gives on the CPU.
struct GpuTraceResult {
  int width = 0;
  int height = 0;
  /// nodes_visited, box_tests, prim_tests, nodes_culled and nodes_missed
  /// (the BVH leaves the other counters at 0 for closest-hit queries).
  std::vector<RayStats> stats;
  /// prim (scene order, kInvalidId on a miss), t and ng (the hit triangle's
  /// triangle_normal). u and v are not computed (0).
  std::vector<Hit> hits;
  double trace_ms = 0.0;     ///< dispatch until the GPU finished (glFinish), wall time
  double readback_ms = 0.0;  ///< copying the per-pixel results back
};

/// Whether pixel `i` of a GPU trace has exactly these figures: the five
/// counters, the hit primitive and a bit-identical hit distance (the CPU's,
/// from Bvh::closest_hit with statistics for the same ray, or another
/// trace's pixel).
bool gpu_pixel_matches(const GpuTraceResult& gpu, std::size_t i, const RayStats& stats, const Hit& hit);

/// Why the GPU cannot trace `structure_name` with `query`; empty when it can.
/// Only the binary BVH is traced on the GPU ("--device gpu: only the bvh
/// structure is traced on the GPU" is the CLI's wording of the first case).
std::string gpu_trace_unsupported(const std::string& structure_name);

class GpuBvhTracer {
 public:
  /// Compiles shaders/trace_bvh.comp in the current context. Throws
  /// ShaderError or GlError.
  GpuBvhTracer();

  /// Copies the BVH's nodes and leaf-ordered triangles to the GPU and keeps
  /// the leaf-to-scene id map. Throws GlError when the buffers exceed the
  /// context's storage-block limit.
  void upload(const Bvh& bvh);
  /// Whether a BVH has been uploaded.
  bool ready() const { return uploaded_; }
  /// Node count of the uploaded BVH.
  std::size_t node_count() const { return node_count_; }

  /// Traces one primary ray per pixel (core's primary_ray) of a W×H image.
  /// Honours the triangle test, ordered, back_to_front and xray of `query`.
  /// Throws std::invalid_argument for a non-positive size, std::logic_error
  /// before upload(). The same as begin(), trace_rows(height), result().
  GpuTraceResult trace(const Camera& camera, int width, int height, const QueryOptions& query);
  /// The same into `into`, reusing its storage (see result(GpuTraceResult&)).
  void trace(const Camera& camera, int width, int height, const QueryOptions& query, GpuTraceResult& into);

  // ---- in row bands (the GUI spreads one image over its frames) ----------
  /// Starts a banded trace of a W×H image: fixes the camera, size and query
  /// and marks every pixel untraced: until a band traces its row, a pixel
  /// reads (read_pixels, result) with all counters kUntraced and a miss.
  /// Throws like trace(). A pixel traced in any band gets exactly trace()'s
  /// figures.
  void begin(const Camera& camera, int width, int height, const QueryOptions& query);
  /// Dispatches the next band, rows [rows_done(), rows_done() + rows)
  /// clipped to the image, and waits for it (glFinish). Returns the band's
  /// wall ms (also added to result().trace_ms). Throws std::logic_error
  /// without begin(), std::invalid_argument for rows < 1, GlError.
  double trace_rows(int rows);
  int rows_done() const { return rows_done_; }
  int width() const { return width_; }          ///< of the trace begun last
  double trace_ms() const { return band_ms_; }  ///< its bands' wall ms so far
  int rows_total() const { return height_; }
  bool finished() const { return height_ > 0 && rows_done_ >= height_; }
  /// Reads the whole image back as it stands (rows no band traced yet read
  /// untraced); trace_ms is the sum of the bands so far.
  GpuTraceResult result() const;
  /// The same into `into`, reusing its vectors' storage: a 1920x1080 result
  /// is about 140 MB, and a fresh one costs more to allocate and first touch
  /// than the GPU takes to trace it (measured, docs/performance.md "GPU path").
  void result(GpuTraceResult& into) const;
  /// Reads the image as it stands in place: copies it on the GPU into a
  /// buffer in client memory, maps that and calls `use` with its pixels
  /// (row-major from the top row; rows no band traced yet read untraced), then
  /// unmaps it, also when `use` throws. `use` may read them on all threads;
  /// they are valid only during the call. Returns the ms of the copy and the
  /// mapping (not of `use`). Throws std::logic_error before begin(), GlError.
  double read_pixels(const std::function<void(std::span<const GpuPixel>)>& use) const;
  /// A pixel's counters as core's RayStats (the others 0).
  static RayStats stats_of(const GpuPixel& p);
  /// A pixel's hit as Bvh::closest_hit gives it: prim in scene order, t, and
  /// the triangle's triangle_normal (u, v 0); a miss is Hit{}.
  Hit hit_of(const GpuPixel& p) const;
  /// Whether hit_of(p) is a hit.
  bool is_hit(const GpuPixel& p) const { return p.prim != kInvalidId && p.prim < prim_ids_.size(); }
  /// hit_of(p).prim alone: the scene-order triangle, kInvalidId on a miss.
  std::uint32_t scene_prim(const GpuPixel& p) const { return is_hit(p) ? prim_ids_[p.prim] : kInvalidId; }
  /// Every counter of an untraced pixel (see begin()).
  static constexpr std::uint32_t kUntraced = 0xFFFFFFFFu;

 private:
  ShaderProgram program_;
  GlObject nodes_;
  GlObject tris_;
  GlObject out_;       ///< what the shader writes (never mapped)
  GlObject readback_;  ///< out_ copied into client memory, mapped by result()
  std::size_t out_bytes_ = 0;
  std::size_t node_count_ = 0;
  std::vector<std::uint32_t> prim_ids_;  ///< leaf order -> scene order
  std::vector<glm::vec3> normals_;       ///< triangle_normal per leaf-order triangle
  bool uploaded_ = false;
  int width_ = 0, height_ = 0;  ///< of the banded trace begun last
  int rows_done_ = 0;
  double band_ms_ = 0.0;  ///< its bands' wall ms so far
};

/// Called once per block of a GPU metric image with the block's first pixel,
/// its pixels and their values (on all threads, for disjoint blocks).
using GpuBlockVisit =
    std::function<void(std::size_t i0, std::span<const GpuPixel> pixels, std::span<const float> values)>;

/// The metric image of the trace begun last on `tracer` (its bands so far;
/// render_ms is their trace time), made in one pass over the pixels read in
/// place (read_pixels: no GpuTraceResult), into `into` (storage reused):
/// metric_value of each pixel's stats_of, hit_of and, for the shaded metric
/// alone, core's primary_ray of `camera`, block by block on all threads
/// (metric_image_by_blocks), `visit` (when given) called after each block.
/// Returns read_pixels' ms. Throws std::invalid_argument when the trace's
/// size is not opts' size, BuildCancelled when opts.progress cancels, and as
/// read_pixels.
double gpu_metric_image(const GpuBvhTracer& tracer, const Camera& camera, const HeatmapOptions& opts,
                        HeatmapFigures* figures, MetricImage& into, const GpuBlockVisit& visit = {});

/// render_metric on the GPU: the same MetricImage (and figures; render_ms is
/// the GPU trace time) as core's render_metric(bvh, camera, opts) gives,
/// through metric_value. `readback_ms`, when
/// given, gets read_pixels' ms.
MetricImage gpu_render_metric(GpuBvhTracer& tracer, const Camera& camera, const HeatmapOptions& opts,
                              HeatmapFigures* figures = nullptr, double* readback_ms = nullptr);

}  // namespace accelviz
