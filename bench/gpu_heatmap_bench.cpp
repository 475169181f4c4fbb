// GPU heatmap benchmark (issue 11's GPU target: a 1M-triangle heatmap at
// 1920x1080 in <= 16 ms on a real GPU). Traces the primary rays of one
// heatmap, seen from the scene's framing camera (frame_bounds), in
// the compute shader (shaders/trace_bvh.comp through GpuBvhTracer, the path of
// `render --device gpu`) in an EGL context, several times, and checks each
// pixel's counters, hit and distance against the CPU's counted walk:
//
//   accelviz_gpu_bench SCENE [WxH] [RUNS] [gpu|any]
//   accelviz_gpu_bench 'builtin:teapot?size=1000000' 1920x1080 10 gpu
//
// SCENE is any scene spec (file or builtin:...); WxH defaults to 1920x1080,
// RUNS to 10; `gpu` takes a hardware EGL device only, `any` (the default)
// also Mesa's software device. Prints one JSON object: the scene, its
// triangles, the size, the device (GL_RENDERER, EGL device file, software or
// not), setup_ms (shader compile and upload), trace_ms of every run (dispatch
// until the GPU finished) with their min and median, readback_ms, cpu_ms (the
// CPU's counted walk over the same pixels on all threads) and
// heatmap_* (the whole `--metric nodes` heatmap up to its colours, min(RUNS, 5)
// times: the median of all of it and of its trace, readback (the copy and
// mapping), metric image (read in place from the mapping, the readback
// included) and colour steps), gui_* (the GUI's frame of the same heatmap as
// GpuHeatmap makes it, min(RUNS, 5) times: all of it, its trace, its finish
// (readback, metric image, pixel figures, summary) and that readback),
// cpu_heatmap_ms (the same heatmap made by the CPU: render_metric
// on all threads, then colorize),
// mismatched_pixels (pixels whose figures differ from the CPU's), sorted by
// what differs: mismatched_counters (a counter), mismatched_hit_prim (the hit
// triangle), mismatched_t_only (same triangle, other distance bits; the
// largest gap in mismatched_t_max_ulps). The exit
// status is 0 when every pixel matched, 1 when some did not, 2 on bad
// arguments or when no context could be made.
//
// Of the GL libraries it needs libEGL alone (no OSMesa, GLFW, ImGui or window), so
// it can be carried to a GPU machine that has none of the others.
#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cstdint>
#include <exception>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/gui/gpu_heatmap.h"
#include "core/accel/bvh/bvh.h"
#include "core/analysis/heatmap.h"
#include "core/query/camera.h"
#include "core/scene/load.h"
#include "core/util/image_size.h"
#include "core/util/parallel.h"
#include "core/util/timing.h"
#include "ui/gl/egl_context.h"
#include "ui/render/gpu_trace.h"

namespace {

using namespace accelviz;

int usage(const std::string& why) {
  std::cerr << "accelviz_gpu_bench: " << why << " (usage: accelviz_gpu_bench SCENE [WxH] [RUNS] [gpu|any])\n";
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || argc > 5) return usage("expected 1 to 4 arguments");
  const std::string spec = argv[1];
  ImageSize size{1920, 1080};
  if (argc > 2) {
    const std::optional<ImageSize> parsed = parse_image_size(argv[2]);
    if (!parsed) return usage("size '" + std::string(argv[2]) + "' is not WxH");
    size = *parsed;
  }
  const int width = size.width, height = size.height;
  int runs = 10;
  if (argc > 3) {
    try {
      runs = std::stoi(argv[3]);
    } catch (const std::exception&) {
      runs = 0;
    }
    if (runs < 1 || runs > 1000) return usage("runs '" + std::string(argv[3]) + "' is not 1..1000");
  }
  const std::string devices = argc > 4 ? argv[4] : "any";
  if (devices != "gpu" && devices != "any") return usage("device '" + devices + "' is not gpu or any");

  try {
    const Scene scene = load_scene(spec);
    if (scene.triangles.empty()) return usage(spec + ": the scene has no triangles");
    BvhOptions bo;
    bo.compute_epo = false;
    const auto bvh_owned = std::make_shared<const Bvh>(scene.triangles, bo);
    const Bvh& bvh = *bvh_owned;
    const Camera camera = frame_bounds(scene.bounds(), static_cast<float>(width) / static_cast<float>(height));
    const QueryOptions query;

    EglContext context(1, 1, devices == "gpu" ? EglContext::Devices::hardware_only : EglContext::Devices::any);
    const auto t_setup = std::chrono::steady_clock::now();
    GpuBvhTracer tracer;
    tracer.upload(bvh);
    const double setup_ms = ms_since(t_setup);

    std::vector<double> trace_ms;
    GpuTraceResult last;
    for (int r = 0; r < runs; ++r) {
      last = tracer.trace(camera, width, height, query);
      trace_ms.push_back(last.trace_ms);
    }
    std::vector<double> sorted = trace_ms;
    std::sort(sorted.begin(), sorted.end());

    // The CPU's counted walk over the same pixels, compared pixel by pixel.
    const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    // A mismatch is also sorted by what differs, for a driver that does not
    // keep the shader's arithmetic: a counter, the hit triangle, or (same
    // triangle) only the distance's bits, with the largest distance in ulps.
    std::atomic<std::size_t> mismatched{0}, counters_differ{0}, prim_differs{0}, t_differs{0};
    std::atomic<std::uint32_t> max_t_ulps{0};
    const auto t_cpu = std::chrono::steady_clock::now();
    parallel_for(static_cast<std::size_t>(height), 0, 1, [&](std::size_t y0, std::size_t y1, unsigned) {
      std::size_t local = 0, local_counters = 0, local_prim = 0, local_t = 0;
      std::uint32_t local_ulps = 0;
      for (std::size_t y = y0; y < y1; ++y)
        for (int x = 0; x < width; ++x) {
          const std::size_t i = y * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
          RayStats s;
          const Hit c = bvh.closest_hit(primary_ray(camera, x, static_cast<int>(y), width, height), query, &s);
          if (gpu_pixel_matches(last, i, s, c)) continue;
          ++local;
          if (!gpu_pixel_matches(last, i, s, last.hits[i])) ++local_counters;  // the GPU's own hit: counters only
          if (c.prim != last.hits[i].prim) {
            ++local_prim;
          } else if (std::bit_cast<std::uint32_t>(c.t) != std::bit_cast<std::uint32_t>(last.hits[i].t)) {
            ++local_t;
            const auto a = static_cast<std::int64_t>(std::bit_cast<std::uint32_t>(c.t));
            const auto b = static_cast<std::int64_t>(std::bit_cast<std::uint32_t>(last.hits[i].t));
            local_ulps = std::max(local_ulps, static_cast<std::uint32_t>(std::min<std::int64_t>(
                                                  a > b ? a - b : b - a, std::numeric_limits<std::uint32_t>::max())));
          }
        }
      mismatched += local;
      counters_differ += local_counters;
      prim_differs += local_prim;
      t_differs += local_t;
      std::uint32_t seen = max_t_ulps.load();
      while (local_ulps > seen && !max_t_ulps.compare_exchange_weak(seen, local_ulps)) {
      }
    });
    const double cpu_ms = ms_since(t_cpu);

    // The whole heatmap as `render --device gpu --metric nodes` makes it, a
    // few times: trace, metric image read in place from the readback, colours
    // (no PNG), beside the CPU's (render_metric over the same BVH on all
    // threads, same colours). Then the GUI's frame (GpuHeatmap: trace, metric
    // image, pixel figures and summary, as the View panel's "Trace on: GPU"
    // makes it; the texture upload and drawing are not counted).
    HeatmapOptions hopts;
    hopts.width = width;
    hopts.height = height;
    hopts.metric = HeatMetric::nodes;
    hopts.query = query;
    const int heat_runs = std::min(runs, 5);
    std::vector<double> heat_ms, heat_trace, heat_readback, heat_metric, heat_colour, cpu_heat_ms;
    MetricImage img;  // reused, as a GUI would reuse its storage (the first run allocates it)
    for (int r = 0; r < heat_runs; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      tracer.begin(camera, width, height, query);
      tracer.trace_rows(height);
      const auto t1 = std::chrono::steady_clock::now();
      heat_readback.push_back(gpu_metric_image(tracer, camera, hopts, nullptr, img));
      const auto t2 = std::chrono::steady_clock::now();
      const RgbImage rgb = colorize(img, ColorizeOptions{});
      heat_ms.push_back(ms_since(t0));
      heat_trace.push_back(tracer.trace_ms());
      heat_metric.push_back(std::chrono::duration<double, std::milli>(t2 - t1).count());
      heat_colour.push_back(ms_since(t2));
      const auto c0 = std::chrono::steady_clock::now();
      const RgbImage cpu_rgb = colorize(render_metric(bvh, camera, hopts, nullptr), ColorizeOptions{});
      cpu_heat_ms.push_back(ms_since(c0));
      if (cpu_rgb.pixels.size() != rgb.pixels.size()) throw std::runtime_error("heatmap sizes differ");
    }
    HeatmapRequest request;
    auto built = std::make_shared<BuiltStructure>();
    built->accel = bvh_owned;
    request.structure = built;
    request.camera = camera;
    request.options = hopts;
    GpuHeatmap gui;
    std::vector<double> gui_ms, gui_trace, gui_finish, gui_readback;
    std::shared_ptr<const HeatmapFrame> shown;  // held while the next is made, as the window shows it
    for (int r = 0; r < heat_runs; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      std::shared_ptr<const HeatmapFrame> frame = gui.trace(request, static_cast<std::uint64_t>(r + 1));
      gui_ms.push_back(ms_since(t0));
      if (!frame || frame->pixels.size() != pixels) throw std::runtime_error("the GUI's GPU frame is incomplete");
      gui_trace.push_back(gui.progress().trace_ms);
      gui_finish.push_back(gui.last_finish_ms());
      gui_readback.push_back(gui.last_readback_ms());
      shown = std::move(frame);
    }

    const nlohmann::json out = {
        {"scene", spec},
        {"triangles", scene.triangles.size()},
        {"width", width},
        {"height", height},
        {"rays", pixels},
        {"gpu_renderer", context.info().renderer},
        {"gpu_version", context.info().version},
        {"gpu_device_file", context.device_file()},
        {"gpu_software", context.software()},
        {"setup_ms", setup_ms},
        {"trace_ms", trace_ms},
        {"trace_ms_min", sorted.front()},
        {"trace_ms_median", sorted[sorted.size() / 2]},
        {"readback_ms", last.readback_ms},
        {"cpu_threads", resolve_threads(0)},
        {"cpu_ms", cpu_ms},
        {"heatmap_runs", heat_runs},
        {"heatmap_ms", heat_ms},
        {"heatmap_ms_median", median(heat_ms)},
        {"heatmap_trace_ms_median", median(heat_trace)},
        {"heatmap_readback_ms_median", median(heat_readback)},
        {"heatmap_metric_ms_median", median(heat_metric)},
        {"heatmap_colour_ms_median", median(heat_colour)},
        {"gui_frame_ms", gui_ms},
        {"gui_frame_ms_median", median(gui_ms)},
        {"gui_trace_ms_median", median(gui_trace)},
        {"gui_finish_ms_median", median(gui_finish)},
        {"gui_readback_ms_median", median(gui_readback)},
        {"cpu_heatmap_ms", cpu_heat_ms},
        {"cpu_heatmap_ms_median", median(cpu_heat_ms)},
        {"mismatched_pixels", mismatched.load()},
        {"mismatched_counters", counters_differ.load()},
        {"mismatched_hit_prim", prim_differs.load()},
        {"mismatched_t_only", t_differs.load()},
        {"mismatched_t_max_ulps", max_t_ulps.load()},
    };
    std::cout << out.dump() << "\n";
    return mismatched.load() == 0 ? 0 : 1;
  } catch (const std::exception& e) {  // GlError, ShaderError, a scene that does not load
    std::cerr << "accelviz_gpu_bench: " << e.what() << "\n";
    return 2;
  }
}
