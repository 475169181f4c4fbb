#include "app/gui/gpu_heatmap.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/accel/bvh/bvh.h"

namespace accelviz {

std::shared_ptr<const HeatmapFrame> GpuHeatmap::trace(const HeatmapRequest& r, std::uint64_t id) {
  const Bvh* bvh = r.structure ? dynamic_cast<const Bvh*>(r.structure->accel.get()) : nullptr;
  if (!bvh) throw std::invalid_argument("only the bvh structure is traced on the GPU");
  if (!tracer_) tracer_ = std::make_unique<GpuBvhTracer>();
  if (uploaded_ != r.structure) {
    tracer_->upload(*bvh);
    uploaded_ = r.structure;
  }
  HeatmapOptions ho;
  ho.metric = r.metric;
  ho.width = r.width;
  ho.height = r.height;
  ho.query = r.query;
  ho.c_trav = r.c_trav;
  ho.c_isect = r.c_isect;
  HeatmapFigures fig;
  GpuTraceResult raw;
  auto frame = std::make_shared<HeatmapFrame>();
  frame->image = gpu_render_metric(*tracer_, r.camera, ho, &fig, &raw);
  frame->id = id;
  frame->stride = 1;
  frame->complete = true;
  frame->request = r;

  const std::size_t n = frame->image.values.size();
  frame->pixels.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    PixelFigures& p = frame->pixels[i];
    p.value = frame->image.values[i];
    p.nodes = raw.stats[i].nodes_visited;
    p.prims = raw.stats[i].prim_tests;
    p.prim = raw.hits[i].prim;
    p.t = raw.hits[i].t;
  }
  frame->summary = summarise_pixels(frame->pixels, fig.render_ms);
  return frame;
}

}  // namespace accelviz
