#include "app/gui/scene_view.h"

#include <algorithm>
#include <cmath>

#include "core/accel/tlas/tlas.h"
#include "ui/app/hot_nodes.h"
#include "ui/app/instance_colors.h"
#include "ui/render/box_selection.h"

namespace accelviz {

namespace {
constexpr std::uint32_t kNoInstance = 0xFFFFFFFFu;  ///< NodeBox::instance of a box that is no instance's
}  // namespace

bool SceneView::sync(const AppState& app) {
  bool changed = false;
  const BuiltStructure* built = app.current().get();
  const void* scene = built ? static_cast<const void*>(built->scene.get()) : nullptr;
  if (scene != scene_) {
    renderer_.set_triangles(built ? std::span<const Triangle>(built->scene->scene.triangles)
                                  : std::span<const Triangle>());
    scene_ = scene;
    colored_ = false;  // set_triangles dropped the colours
    changed = true;
  }
  // Per-instance colours: a two-level structure's view, when asked for.
  const bool colored = built && app.config().view.instance_colors && built->nodes.kind() == "tlas";
  if (colored != colored_) {
    renderer_.set_triangle_colors(colored ? triangle_instance_colors(built->scene->scene) : std::vector<glm::vec3>());
    colored_ = colored;
    changed = true;
  }
  if (app.heatmap() && app.heatmap() != heatmap_frame_) {
    heatmap_frame_ = app.heatmap();
    renderer_.set_heatmap(app.heatmap()->image);
    has_heatmap_ = true;
    changed = true;
  }
  if (const int map = static_cast<int>(app.config().view.colormap); map != colormap_) {
    renderer_.set_colormap(app.config().view.colormap);
    colormap_ = map;
    changed = true;
  }
  const std::string box_key_before = box_key_, ray_key_before = ray_key_;
  upload_boxes(app);
  upload_ray(app);
  return changed || box_key_ != box_key_before || ray_key_ != ray_key_before;
}

void SceneView::upload_boxes(const AppState& app) {
  const ViewSettings& v = app.config().view;
  const BuiltStructure* built = app.current().get();
  // Everything the selection and its colours depend on.
  const ViewInsight* insight =
      box_insight_.insight && box_insight_.insight->built.get() == built ? box_insight_.insight.get() : nullptr;
  const RegionTouch* region = insight ? box_insight_.region.get() : nullptr;
  // A two-level structure's bottom level: its BLAS boxes in world space.
  const Tlas* blas_of = built && built->nodes.kind() == "tlas" && v.box_level == BoxLevel::blas
                            ? dynamic_cast<const Tlas*>(built->accel.get())
                            : nullptr;
  // Hot-node visits are counted per node of the structure's table (the top
  // level for `tlas`), so they colour that level only.
  const bool by_visits = insight && box_insight_.color_by_visits && !blas_of;
  // Primitives the selected region's rays tested, on the surface.
  if (static_cast<const void*>(region) != region_uploaded_) {
    region_uploaded_ = region;
    std::vector<std::uint32_t> prims;
    if (region && built && built->nodes.kind() != "voxels") {
      const std::size_t n = built->scene->scene.triangles.size();
      for (const std::uint32_t p : region->prims)
        if (p < n) prims.push_back(p);
    }
    renderer_.set_highlighted_primitives(prims);
  }
  const std::string key = std::to_string(reinterpret_cast<std::uintptr_t>(insight)) + "/" + std::to_string(by_visits) +
                          "/" + std::to_string(reinterpret_cast<std::uintptr_t>(region)) + "/" +
                          std::to_string(reinterpret_cast<std::uintptr_t>(built)) + "/" +
                          std::to_string(static_cast<int>(v.box_mode)) + "/" + std::to_string(v.box_depth) + "/" +
                          std::to_string(v.box_depth_last) + "/" + std::to_string(v.box_node) + "/" +
                          std::to_string(static_cast<int>(v.box_color)) + "/" +
                          std::to_string(static_cast<int>(v.colormap)) + "/" + std::to_string(blas_of != nullptr) +
                          "/" + std::to_string(v.box_instance) + "/" + std::to_string(v.instance_colors);
  if (key == box_key_) return;
  box_key_ = key;
  boxes_drawn_ = 0;
  boxes_matched_ = 0;
  boxes_visit_max_ = 0;
  boxes_truncated_ = false;
  boxes_of_region_ = region != nullptr;
  boxes_by_visits_ = by_visits;
  if (!built || built->nodes.empty()) {
    renderer_.set_boxes({});
    return;
  }
  NodeSelection sel;
  sel.mode = v.box_mode;
  sel.depth = static_cast<std::uint32_t>(v.box_depth);
  sel.depth_last = static_cast<std::uint32_t>(v.box_range_last());
  sel.node = static_cast<std::uint32_t>(v.box_node);
  StructureNodes::Selection s;
  if (region) {  // the nodes the region's rays entered, instead of the view's selection
    s.matched = region->nodes.size();
    for (const std::uint32_t id : region->nodes) {
      if (s.boxes.size() >= kMaxBoxes) {
        s.truncated = true;
        break;
      }
      if (const StructureNode* n = built->nodes.node(id))
        s.boxes.push_back({n->bounds, id, n->depth, n->leaf, n->sah_share});
      else if (const auto b = built->nodes.box(id))
        s.boxes.push_back({*b, id, 1, true, 0.0f});
    }
  } else if (blas_of) {
    s = select_blas_boxes(*blas_of, sel, kMaxBoxes, v.box_instance);
  } else {
    s = built->nodes.select(sel, kMaxBoxes);
  }
  boxes_drawn_ = s.boxes.size();
  boxes_matched_ = std::max<std::uint64_t>(s.matched, s.boxes.size());
  boxes_truncated_ = s.truncated;

  std::vector<ColoredBox> boxes;
  boxes.reserve(s.boxes.size());
  float max_share = 0.0f;
  for (const NodeBox& b : s.boxes) max_share = std::max(max_share, b.sah_share);
  // Hot nodes: every box on the colour map by its visits (the hottest on top).
  const std::vector<glm::vec4> hot =
      by_visits ? visit_colors(s.boxes, insight->visits, v.colormap) : std::vector<glm::vec4>();
  if (by_visits) boxes_visit_max_ = max_visit_count(s.boxes, insight->visits);
  for (std::size_t i = 0; i < s.boxes.size(); ++i) {
    const NodeBox& b = s.boxes[i];
    ColoredBox c;
    c.box = b.bounds;
    if (by_visits) {
      c.color = hot[i];
    } else if (region) {
      c.color = glm::vec4(1.0f, 0.55f, 0.1f, 1.0f);
    } else if (v.instance_colors && b.instance != kNoInstance) {
      c.color = glm::vec4(instance_color(b.instance), 1.0f);  // the colour its triangles have
    } else if (v.box_color == BoxColorBy::depth) {
      c.color = glm::vec4(qualitative_color(b.depth), 1.0f);
    } else {
      // Shares span orders of magnitude (the root's area against a leaf's):
      // a square root keeps the small ones distinguishable.
      const float t = max_share > 0.0f ? std::sqrt(b.sah_share / max_share) : 0.0f;
      c.color = glm::vec4(colormap(v.colormap, t), 1.0f);
    }
    boxes.push_back(c);
  }
  renderer_.set_boxes(boxes);
}

void SceneView::upload_ray(const AppState& app) {
  const auto& insp = app.inspection();
  const BuiltStructure* built = app.current().get();
  const std::string key = std::to_string(app.inspection_version()) + "/" + std::to_string(app.replay_step()) + "/" +
                          std::to_string(reinterpret_cast<std::uintptr_t>(built));
  if (key == ray_key_) return;
  ray_key_ = key;
  if (!insp || !built) {
    renderer_.clear_ray_path();
    return;
  }
  RayPath path = make_ray_path(insp->ray, insp->hit, built->scene->scene.bounds());
  const ReplayState r = replay_upto(insp->trace, app.replay_step());
  // The current step's node last, in the "last visit" colour (replay_box_ids).
  for (std::uint32_t id : replay_box_ids(insp->trace, app.replay_step()))
    if (const auto b = built->nodes.box(id)) path.visited.push_back(*b);
  // Voxel "primitives" are voxels, not triangles: nothing to highlight.
  if (built->nodes.kind() != "voxels") {
    const std::size_t n = built->scene->scene.triangles.size();
    for (std::uint32_t p : r.tested)
      if (p < n) path.highlighted.push_back(p);
  }
  renderer_.set_ray_path(path);
}

glm::vec2 SceneView::heatmap_range(const AppState& app) const {
  return renderer_.heatmap_range(render_view(app).heatmap);
}

RenderView SceneView::render_view(const AppState& app) const {
  const ViewSettings& v = app.config().view;
  RenderView r;
  r.camera = app.camera();
  r.msaa_samples = v.msaa;
  r.show_mesh = v.show_mesh;
  r.show_wireframe = v.show_wireframe;
  r.show_boxes = v.show_boxes;
  r.boxes_through_mesh = v.boxes_through_mesh;
  r.show_ray_path = v.show_ray_path && app.inspection().has_value();
  r.show_quads = false;
  HeatmapView& h = r.heatmap;
  h.mode = !has_heatmap_                              ? HeatmapMode::off
           : v.heatmap == HeatmapDisplay::full_screen ? HeatmapMode::full_screen
           : v.heatmap == HeatmapDisplay::blend       ? HeatmapMode::blend
                                                      : HeatmapMode::off;
  h.opacity = v.opacity;
  h.auto_scale = v.auto_scale;
  h.range_min = v.scale_min;
  h.range_max = v.scale_max;
  h.show_legend = v.show_legend;
  // The legend in the traced structure's words: a grid's nodes are cells.
  if (heatmap_frame_ && heatmap_frame_->request.structure && heatmap_frame_->request.structure->accel)
    h.title = metric_short_label(heatmap_frame_->image.metric, heatmap_frame_->request.structure->accel->name());
  return r;
}

void SceneView::draw(const AppState& app, int width, int height) {
  renderer_.render(render_view(app), width, height);
}

}  // namespace accelviz
