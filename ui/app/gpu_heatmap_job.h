#pragma once
// The seam between AppState (GL-free) and the GUI's GPU heatmap
// (app/gui/gpu_heatmap.h, over the window's GL context): a trace of one
// HeatmapRequest spread over frames in row bands, so the window keeps
// drawing while the compute shader works. AppState starts a job when the
// view changes, steps it once per frame within a time budget (the View
// option heatmap-gpu-ms), and shows the frame only once it is finished.
#include <algorithm>
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

/// The tracing budget of one frame's GpuHeatmapJob::step: `setting_ms` (the
/// View option heatmap-gpu-ms), or as long as the rest of the previous frame
/// took (`last_frame_ms` from one update to the next, less `last_step_ms` of
/// GPU stepping in it; capped at 100 ms) when that is longer: on a slow GL
/// (llvmpipe draws a frame in tens of ms) the trace then gets about half the
/// time instead of a sliver, and the window still draws at about half its
/// rate. A setting of 0 stays "one band a frame"; `last_frame_ms` 0 (no
/// previous frame) leaves the setting as it is.
inline double gpu_heatmap_budget_ms(double setting_ms, double last_frame_ms, double last_step_ms) {
  const double frame_other_ms = last_frame_ms > 0.0 ? last_frame_ms - last_step_ms : 0.0;
  if (setting_ms > 0.0 && frame_other_ms > 0.0) return std::max(setting_ms, std::min(frame_other_ms, 100.0));
  return setting_ms;
}

}  // namespace accelviz
