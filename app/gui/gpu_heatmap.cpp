#include "app/gui/gpu_heatmap.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "core/accel/bvh/bvh.h"
#include "core/util/timing.h"

namespace accelviz {
namespace {

constexpr int kBandRows = 8;  // one row of trace_bvh.comp's 8x8 work groups

}  // namespace

void GpuHeatmap::start(const HeatmapRequest& r, std::uint64_t id) {
  running_ = false;
  progress_ = {};
  const Bvh* bvh = r.structure ? dynamic_cast<const Bvh*>(r.structure->accel.get()) : nullptr;
  if (!bvh) throw std::invalid_argument("only the bvh structure is traced on the GPU");
  if (!tracer_) tracer_ = std::make_unique<GpuBvhTracer>();
  if (uploaded_ != r.structure) {
    // Spare frames let go of the structure they showed (it may be freed now).
    frames_.release_requests();
    uploaded_.reset();
    tracer_->upload(*bvh);
    uploaded_ = r.structure;
  }
  tracer_->begin(r.camera, r.options.width, r.options.height, r.options.query);
  request_ = r;
  id_ = id;
  running_ = true;
  progress_.rows = r.options.height;
  // ms_per_pixel_ and last_rows_ carry over: the previous view's cost sizes
  // this one's first band (a camera being dragged restarts every frame).
}

std::unique_ptr<GpuBvhTracer> GpuHeatmap::fresh_tracer() const {
  return tracer_ ? std::make_unique<GpuBvhTracer>() : nullptr;
}

void GpuHeatmap::replace_tracer(std::unique_ptr<GpuBvhTracer> fresh) {
  if (!fresh) return;
  running_ = false;
  frames_.release_requests();
  uploaded_.reset();
  tracer_ = std::move(fresh);
}

std::shared_ptr<const HeatmapFrame> GpuHeatmap::step(double budget_ms) {
  if (!running_) return nullptr;
  try {
    double spent = 0.0;
    do {
      // Size the band to what is left of the budget at the last band's cost
      // per pixel, at most twice the last band (the cost varies over the
      // image), whole work-group rows when more than one; 8 rows when the
      // cost is unknown or the budget is 0.
      int rows = kBandRows;
      if (budget_ms > 0.0 && ms_per_pixel_ > 0.0 && last_rows_ > 0) {
        const double left = budget_ms - spent;
        const double fit = left / (ms_per_pixel_ * static_cast<double>(request_.options.width));
        rows = static_cast<int>(std::clamp(fit, 1.0, static_cast<double>(std::max(kBandRows, 2 * last_rows_))));
        if (rows > kBandRows) rows -= rows % kBandRows;
      }
      const int before = tracer_->rows_done();
      const double ms = tracer_->trace_rows(rows);
      const int traced = tracer_->rows_done() - before;
      spent += ms;
      last_rows_ = traced;
      if (traced > 0) ms_per_pixel_ = ms / (static_cast<double>(traced) * request_.options.width);
      progress_.rows_done = tracer_->rows_done();
      progress_.trace_ms += ms;
      ++progress_.bands;
    } while (!tracer_->finished() && budget_ms > 0.0 && spent < budget_ms);
    if (!tracer_->finished()) return nullptr;
    return finish();
  } catch (...) {
    running_ = false;
    throw;
  }
}

std::shared_ptr<const HeatmapFrame> GpuHeatmap::finish() {
  running_ = false;
  const auto t0 = std::chrono::steady_clock::now();
  std::shared_ptr<HeatmapFrame> frame = frames_.take(1);  // one shown while the other is written
  const std::size_t n = static_cast<std::size_t>(request_.options.width) * request_.options.height;
  frame->pixels.resize(n);
  HeatmapFigures fig;
  // One pass over the pixels read in place: the metric image, and each
  // block's pixel figures and their tally while the block is in cache (the
  // tallies merged in block order, as summarise_pixels does).
  PixelFigures* out = frame->pixels.data();
  std::vector<PixelTally> tallies((n + kMetricBlock - 1) / kMetricBlock);
  last_readback_ms_ =
      gpu_metric_image(*tracer_, request_.camera, request_.options, &fig, frame->image,
                       [&](std::size_t i0, std::span<const GpuPixel> px, std::span<const float> values) {
                         for (std::size_t k = 0; k < px.size(); ++k) {
                           PixelFigures& p = out[i0 + k];
                           p = PixelFigures{};  // every field: the frame may hold an earlier image
                           p.value = values[k];
                           p.nodes = px[k].nodes_visited;
                           p.prims = px[k].prim_tests;
                           p.prim = tracer_->scene_prim(px[k]);  // as hit_of, without the normal
                           p.t = p.prim != kInvalidId ? px[k].t : Hit{}.t;
                           tallies[i0 / kMetricBlock].add(p);
                         }
                       });
  frame->id = id_;
  frame->stride = 1;
  frame->complete = true;
  frame->request = request_;
  PixelTally total;
  for (const PixelTally& t : tallies) total.merge(t);
  frame->summary = total.summary(fig.render_ms);
  last_finish_ms_ = ms_since(t0);
  return frame;
}

std::shared_ptr<const HeatmapFrame> GpuHeatmap::trace(const HeatmapRequest& r, std::uint64_t id) {
  start(r, id);
  std::shared_ptr<const HeatmapFrame> f;
  while (!f && running_) f = step(1e9);
  return f;
}

}  // namespace accelviz
