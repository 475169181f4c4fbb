#pragma once
// The heatmap's primary rays traced on the GPU: shaders/trace_bvh.comp, one
// compute invocation per pixel over the binary BVH's flat node array and its
// leaf-ordered triangles (two std430 storage buffers), counting what the
// CPU's instrumented BVH traversal counts. Needs a current GL 4.5 context
// (OsMesaContext headless, the GUI's window context); every call must come
// from the thread that context is current on.
//
// The per-pixel figures come back as core's RayStats and Hit, so the
// heatmap's metric values, colour map, legend and PNG writing are core's
// (metric_value, colorize, write_png): only the tracing moves.
#include <cstdint>
#include <string>
#include <vector>

#include "core/accel/accel.h"
#include "core/accel/bvh/bvh.h"
#include "core/analysis/heatmap.h"
#include "core/scene/scene.h"
#include "ui/gl/gl_object.h"
#include "ui/gl/shader.h"

namespace accelviz {

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
  /// before upload().
  GpuTraceResult trace(const Camera& camera, int width, int height, const QueryOptions& query);

 private:
  ShaderProgram program_;
  GlObject nodes_;
  GlObject tris_;
  GlObject out_;
  std::size_t out_bytes_ = 0;
  std::size_t node_count_ = 0;
  std::vector<std::uint32_t> prim_ids_;  ///< leaf order -> scene order
  std::vector<glm::vec3> normals_;       ///< triangle_normal per leaf-order triangle
  bool uploaded_ = false;
};

/// render_metric on the GPU: the same MetricImage (and figures; render_ms is
/// the GPU trace time) as core's render_metric(bvh, camera, opts) gives,
/// through metric_value. opts.threads and opts.progress are not used.
MetricImage gpu_render_metric(GpuBvhTracer& tracer, const Camera& camera, const HeatmapOptions& opts,
                              HeatmapFigures* figures = nullptr, GpuTraceResult* raw = nullptr);

}  // namespace accelviz
