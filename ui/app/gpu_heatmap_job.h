#pragma once
// The seam between AppState (GL-free) and the GUI's GPU heatmap
// (app/gui/gpu_heatmap.h, over the window's GL context): a trace of one
// HeatmapRequest spread over frames in row bands, so the window keeps
// drawing while the compute shader works. AppState starts a job when the
// view changes, steps it once per frame within a time budget (the View
// option heatmap-gpu-ms), and shows the frame only once it is finished.
#include <cstdint>
#include <memory>

#include "ui/app/heatmap_worker.h"

namespace accelviz {

class GpuHeatmapJob {
 public:
  struct Progress {
    int rows_done = 0;  ///< image rows traced so far
    int rows = 0;       ///< image rows in all
    int bands = 0;      ///< dispatches so far
    double trace_ms = 0.0;
  };
  virtual ~GpuHeatmapJob() = default;
  /// Starts tracing `r` (its frame will carry `id`), dropping any trace in
  /// progress. Throws to say why it cannot (then nothing is running).
  virtual void start(const HeatmapRequest& r, std::uint64_t id) = 0;
  /// Traces the next row bands, stopping once `budget_ms` of tracing is
  /// spent (at least one band; 0: exactly one band). Returns the complete
  /// frame on the step that finishes the image, null before. Throws on GL
  /// trouble (the job is dropped).
  virtual std::shared_ptr<const HeatmapFrame> step(double budget_ms) = 0;
  /// Drops the trace in progress.
  virtual void cancel() = 0;
  /// A trace is started and not finished.
  virtual bool busy() const = 0;
  virtual Progress progress() const = 0;
};

}  // namespace accelviz
