#include "app/render_raster.h"

#include <stdexcept>

#include "app/cli_common.h"
#include "core/analysis/heatmap.h"
#include "core/query/camera.h"

#ifdef ACCELVIZ_HAVE_UI
#include "core/accel/bvh/bvh.h"
#include "ui/gl/osmesa_context.h"
#include "ui/render/box_selection.h"
#include "ui/render/overlays.h"
#include "ui/render/renderer.h"
#include "ui/render/screenshot.h"
#endif

namespace accelviz::cli {

#ifdef ACCELVIZ_HAVE_UI

bool raster_available() { return true; }

void render_raster(const Scene& scene, const Accelerator& accel, const Camera& camera, const ImageSize& size,
                   const RasterOptions& ro, const std::string& metric_name, const std::string& colormap_name,
                   float fixed_max, const QueryOptions& query, float c_trav, float c_isect, unsigned threads,
                   const std::string& out, bool force, nlohmann::json& figures) {
  const auto* bvh = dynamic_cast<const Bvh*>(&accel);
  if (ro.box_depth_last >= 0 && ro.box_depth < 0) throw UsageError("--depth-last needs --depth (the first depth)");
  const bool want_boxes = ro.leaves || ro.box_depth >= 0;
  if (want_boxes && !bvh)
    throw UsageError("--depth/--leaves draw BVH node boxes; structure '" + accel.name() + "' has none to draw");

  OsMesaContext context(size.width, size.height);
  Renderer renderer;
  renderer.set_triangles(scene.triangles);

  RenderView view;
  view.camera = camera;
  view.show_wireframe = ro.wireframe;

  // Node boxes: a depth, a depth range, or the leaves, coloured by depth.
  std::size_t box_count = 0;
  if (want_boxes) {
    BoxSelection sel;
    if (ro.leaves) {
      sel.mode = BoxSelection::Mode::leaves;
    } else {
      sel.mode = BoxSelection::Mode::depth_range;
      sel.depth = static_cast<std::uint32_t>(ro.box_depth);
      sel.depth_last = static_cast<std::uint32_t>(ro.box_depth_last >= 0 ? ro.box_depth_last : ro.box_depth);
      if (sel.depth_last < sel.depth) throw UsageError("--depth-last must not be smaller than --depth");
    }
    const std::vector<SelectedBox> selected = select_bvh_boxes(bvh->nodes(), sel);
    const std::vector<ColoredBox> boxes = color_boxes(selected, BoxColoring{});
    renderer.set_boxes(boxes);
    box_count = boxes.size();
  }
  view.show_boxes = want_boxes;

  // One pixel's ray: its path, the boxes it entered and the primitives it tested.
  if (ro.ray_pixel) {
    const auto [px, py] = *ro.ray_pixel;
    if (px < 0 || py < 0 || px >= size.width || py >= size.height)
      throw UsageError("--ray-pixel " + std::to_string(px) + "," + std::to_string(py) + " lies outside the " +
                       std::to_string(size.width) + "x" + std::to_string(size.height) + " image");
    const Ray ray = primary_ray(ro.ray_camera.value_or(camera), px, py, size.width, size.height);
    VisitTrace trace;
    RayStats stats;
    const Hit hit = accel.closest_hit(ray, query, &stats, &trace);
    RayPath path = make_ray_path(ray, hit, scene.bounds());
    if (bvh) path.visited = entered_boxes(trace, bvh->nodes());
    path.highlighted = tested_primitives(trace);
    renderer.set_ray_path(path);
    figures["ray"] = {{"pixel", {px, py}},
                      {"origin", {ray.origin.x, ray.origin.y, ray.origin.z}},
                      {"direction", {ray.direction.x, ray.direction.y, ray.direction.z}},
                      {"hit", hit.valid()},
                      {"prim", hit.valid() ? static_cast<long long>(hit.prim) : -1},
                      {"t", hit.valid() ? hit.t : -1.0f},
                      {"nodes_visited", stats.nodes_visited},
                      {"prim_tests", stats.prim_tests}};
  }

  // The heatmap blended over the mesh.
  if (ro.blend > 0.0f) {
    const HeatmapOptions ho{.metric = parse_metric(metric_name).value(),
                            .width = size.width,
                            .height = size.height,
                            .threads = threads,
                            .query = query,
                            .c_trav = c_trav,
                            .c_isect = c_isect};
    HeatmapFigures fig;
    const MetricImage img = render_metric(accel, camera, ho, &fig);
    renderer.set_heatmap(img);
    if (colormap_name == "inferno") renderer.set_colormap(ColorMap::inferno);
    else if (colormap_name == "turbo") renderer.set_colormap(ColorMap::turbo);
    else renderer.set_colormap(ColorMap::viridis);
    view.heatmap.mode = ro.blend >= 1.0f ? HeatmapMode::full_screen : HeatmapMode::blend;
    view.heatmap.opacity = ro.blend;
    if (fixed_max > 0.0f) {
      view.heatmap.auto_scale = false;
      view.heatmap.range_min = 0.0f;
      view.heatmap.range_max = fixed_max;
    }
    figures["mean"] = fig.mean;
    figures["max"] = fig.max;
    figures["render_ms"] = fig.render_ms;
  }

  renderer.render(view, size.width, size.height);
  const Rgba8Image pixels = renderer.read_pixels();
  const std::vector<PngText> text{software_png_text()};
  const SaveResult saved = write_screenshot_png(out, pixels, force, text);
  if (!saved) throw std::runtime_error(saved.error);
  figures["boxes"] = box_count;
  figures["view"] = "raster";
  figures["gl_renderer"] = context.info().renderer;
}

#else

bool raster_available() { return false; }

void render_raster(const Scene&, const Accelerator&, const Camera&, const ImageSize&, const RasterOptions&,
                   const std::string&, const std::string&, float, const QueryOptions&, float, float, unsigned,
                   const std::string&, bool, nlohmann::json&) {
  throw UsageError(needs_renderer("--view raster"));
}

#endif

}  // namespace accelviz::cli
