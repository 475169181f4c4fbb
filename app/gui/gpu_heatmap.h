#pragma once
// The GUI's GPU heatmap: the View panel's "Trace on: GPU" traces the current
// view's primary rays with ui/render's GpuBvhTracer (shaders/trace_bvh.comp)
// on the window's GL context, in row bands across frames (GpuHeatmapJob:
// each frame dispatches bands until its time budget is spent, so the window
// keeps drawing and a new view cancels the trace), and hands AppState the
// complete HeatmapFrame once the last band is done (same counts per pixel as
// the CPU worker's last level; no partial image is shown).
// Called on the GUI thread with the window's context current.
#include <cstdint>
#include <memory>

#include "ui/app/gpu_heatmap_job.h"
#include "ui/render/gpu_trace.h"

namespace accelviz {

class GpuHeatmap final : public GpuHeatmapJob {
 public:
  /// Throws ShaderError/GlError (shader or GL trouble) or
  /// std::invalid_argument (not a BVH, bad size); the GPU objects are made
  /// on first use, the BVH uploaded when the structure changed.
  void start(const HeatmapRequest& r, std::uint64_t id) override;
  std::shared_ptr<const HeatmapFrame> step(double budget_ms) override;
  void cancel() override { running_ = false; }
  bool busy() const override { return running_; }
  Progress progress() const override { return progress_; }

  /// For a shader reload (F5, `reload-shaders`): a tracer built from the
  /// shader files as they are now, or null when no trace has been made yet
  /// (the first one reads them anyway). Throws ShaderError/GlError; nothing
  /// is replaced until replace_tracer().
  std::unique_ptr<GpuBvhTracer> fresh_tracer() const;
  /// Takes `fresh` (from fresh_tracer(); null: nothing to do): a trace in
  /// progress is cancelled and the BVH is uploaded again at the next start.
  void replace_tracer(std::unique_ptr<GpuBvhTracer> fresh);

  /// The whole request in one go (start, then bands until done).
  std::shared_ptr<const HeatmapFrame> trace(const HeatmapRequest& r, std::uint64_t id);

  /// Of the last finished frame: ms from the last band's end to the frame
  /// (readback, metric image, pixel figures, summary), and of that the
  /// readback's copy and mapping (GpuBvhTracer::read_pixels).
  double last_finish_ms() const { return last_finish_ms_; }
  double last_readback_ms() const { return last_readback_ms_; }

 private:
  std::shared_ptr<const HeatmapFrame> finish();

  std::unique_ptr<GpuBvhTracer> tracer_;
  /// The frames made, written over once no one holds them (1920x1080 is
  /// 83 MB of pixel figures; a fresh one costs more to allocate and first
  /// touch than the GPU takes to trace it).
  HeatmapFramePool frames_;
  double last_finish_ms_ = 0.0, last_readback_ms_ = 0.0;
  std::shared_ptr<const BuiltStructure> uploaded_;  ///< held: a freed structure's address may come back
  HeatmapRequest request_;
  std::uint64_t id_ = 0;
  bool running_ = false;
  Progress progress_;
  double ms_per_pixel_ = 0.0;  ///< the last band's cost, to size the next (0: unknown)
  int last_rows_ = 0;
};

}  // namespace accelviz
