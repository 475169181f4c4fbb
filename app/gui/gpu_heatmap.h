#pragma once
// The GUI's GPU heatmap: the View panel's "Trace on: GPU" traces the current
// view's primary rays with ui/render's GpuBvhTracer (shaders/trace_bvh.comp)
// on the window's GL context, synchronously, and hands AppState a complete
// HeatmapFrame like the CPU worker's last level (same counts per pixel).
// Called on the GUI thread with the window's context current.
#include <cstdint>
#include <memory>

#include "ui/app/heatmap_worker.h"
#include "ui/render/gpu_trace.h"

namespace accelviz {

class GpuHeatmap {
 public:
  /// Traces `r` (its structure must be a BVH) and returns the frame. Throws
  /// ShaderError/GlError (shader or GL trouble) or std::invalid_argument
  /// (not a BVH); the GPU objects are made on first use, the BVH uploaded
  /// when the structure changed.
  std::shared_ptr<const HeatmapFrame> trace(const HeatmapRequest& r, std::uint64_t id);

 private:
  std::unique_ptr<GpuBvhTracer> tracer_;
  std::shared_ptr<const BuiltStructure> uploaded_;  ///< held: a freed structure's address may come back
};

}  // namespace accelviz
