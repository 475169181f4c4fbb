#pragma once
// The 3D view: keeps the renderer's uploads (triangles, node boxes, heatmap,
// colour map, ray path) in step with the AppState and maps the user's view
// settings onto a RenderView. Needs the window's GL context current.
#include <cstdint>
#include <memory>
#include <string>

#include "ui/app/app_state.h"
#include "ui/app/insight_jobs.h"
#include "ui/render/renderer.h"

namespace accelviz {

/// What the insight views add to the 3D view: the node boxes coloured by
/// hot-node visits, and a heatmap region's nodes and primitives highlighted.
/// Applies only while `insight` was measured on the structure shown.
struct BoxInsight {
  std::shared_ptr<const ViewInsight> insight;
  bool color_by_visits = false;
  std::shared_ptr<const RegionTouch> region;  ///< when set: its nodes are the boxes drawn, its primitives highlighted
};

class SceneView {
 public:
  SceneView() = default;

  /// Uploads what changed since the last call (idempotent: call it as often
  /// as needed, e.g. again right before a screenshot). Returns true when
  /// the picture may have changed (something was uploaded).
  bool sync(const AppState& app);
  /// The RenderView for the app's current settings.
  RenderView render_view(const AppState& app) const;
  /// Draws the view into the renderer's frame (width × height pixels).
  void draw(const AppState& app, int width, int height);

  /// The insight views' overlay (sync() uploads it when it changed).
  void set_box_insight(BoxInsight b) { box_insight_ = std::move(b); }

  Renderer& renderer() { return renderer_; }
  /// The heatmap range the legend shows under the current settings.
  glm::vec2 heatmap_range(const AppState& app) const;
  /// The heatmap image's smallest and largest value.
  ValueRange heatmap_values() const { return renderer_.heatmap_values(); }
  /// Whether a heatmap image has been uploaded.
  bool has_heatmap() const { return has_heatmap_; }

  std::uint64_t boxes_drawn() const { return boxes_drawn_; }
  /// The mesh is drawn in per-instance colours (instance-colors on, a tlas shown).
  bool instance_colored() const { return colored_; }
  bool boxes_truncated() const { return boxes_truncated_; }
  /// Boxes the selection names (more than drawn when the list was cut at kMaxBoxes).
  std::uint64_t boxes_matched() const { return boxes_matched_; }
  /// The boxes drawn are a heatmap region's entered nodes (not the View panel's selection).
  bool boxes_of_region() const { return boxes_of_region_; }
  /// The boxes are coloured by the insight's visit counts (not by the View panel's choice).
  bool boxes_by_visits() const { return boxes_by_visits_; }
  /// The visit count at the top of the boxes' colour ramp (the hottest box
  /// drawn) when they are coloured by visits; else 0.
  std::uint64_t boxes_visit_max() const { return boxes_visit_max_; }

  /// Most boxes drawn at once (llvmpipe draws ~1e5 instanced boxes per frame comfortably).
  static constexpr std::size_t kMaxBoxes = 200000;

 private:
  void upload_boxes(const AppState& app);
  void upload_ray(const AppState& app);

  Renderer renderer_;
  const void* scene_ = nullptr;  ///< identity of the uploaded scene
  /// The uploaded heatmap level, held: the heatmap workers write over frames
  /// that no one holds (HeatmapFramePool, GpuHeatmap), so a level let go
  /// could come back at the same address with another picture.
  std::shared_ptr<const HeatmapFrame> heatmap_frame_;
  BoxInsight box_insight_;
  std::string box_key_;
  const void* region_uploaded_ = nullptr;
  std::string ray_key_;
  int colormap_ = -1;
  bool colored_ = false;  ///< per-instance triangle colours uploaded
  bool has_heatmap_ = false;
  std::uint64_t boxes_drawn_ = 0, boxes_matched_ = 0, boxes_visit_max_ = 0;
  bool boxes_truncated_ = false;
  bool boxes_of_region_ = false, boxes_by_visits_ = false;
};

}  // namespace accelviz
