#pragma once
// The renderer: composes the passes (mesh, boxes, ray path, translucent
// quads, heatmap, legend) into its own framebuffer object, for a GLFW
// window and an OSMesa context alike. Data is uploaded with set_*() when it
// changes; render() draws a RenderView; read_pixels() returns exactly the
// frame (what screenshots write); present() copies it into the window.
//
// Needs a current GlContext (with GL loaded) for its whole life, and that
// context current whenever a member is called.
#include "core/analysis/colormap.h"
#include "core/analysis/heatmap.h"
#include "core/geometry/triangle.h"
#include "ui/gl/shader.h"
#include "ui/render/box_pass.h"
#include "ui/render/box_selection.h"
#include "ui/render/camera_view.h"
#include "ui/render/colored_pass.h"
#include "ui/render/heatmap_pass.h"
#include "ui/render/image.h"
#include "ui/render/legend_pass.h"
#include "ui/render/mesh_pass.h"
#include "ui/render/overlays.h"
#include "ui/render/render_target.h"
#include "ui/render/render_view.h"

#include <cstdint>
#include <span>
#include <vector>

namespace accelviz {

class Renderer {
 public:
  /// Compiles every shader (ShaderError naming file and line on failure).
  Renderer();

  void set_triangles(std::span<const Triangle> triangles);
  /// One colour per triangle of the last set_triangles() for the shaded mesh
  /// (per-instance colours); empty: the view's flat mesh colour. Throws
  /// std::invalid_argument on a count mismatch. set_triangles() clears them.
  void set_triangle_colors(std::span<const glm::vec3> colors);
  void set_boxes(std::span<const ColoredBox> boxes);
  void set_quads(std::span<const TranslucentQuad> quads);
  void set_ray_path(const RayPath& path);
  void clear_ray_path();
  /// Primitives drawn highlighted on the surface regardless of the ray path
  /// (a heatmap region's tested primitives); empty: none.
  void set_highlighted_primitives(std::vector<std::uint32_t> prims, glm::vec4 color = {1.0f, 0.55f, 0.1f, 1.0f});
  /// The metric image shown when RenderView::heatmap.mode is not off.
  void set_heatmap(const MetricImage& image);
  /// The heatmap colour map (viridis until set).
  void set_colormap(ColorMap map);
  /// Any 256-entry table instead of a named map.
  void set_colormap_lut(std::span<const glm::vec3> lut);

  /// Draws `view` into a width × height frame. Each pass is followed by a
  /// glGetError check (GlError names the pass).
  void render(const RenderView& view, int width, int height);
  /// The last frame, rows top-down (row 0 = top), legend included.
  Rgba8Image read_pixels() const;
  /// Copies the last frame into the current context's default framebuffer
  /// (the window), scaled to its size. Binds framebuffer 0 afterwards, so
  /// ImGui can draw on top before swap_buffers.
  void present(int window_width, int window_height) const;

  /// Rebuilds every program from the current shader sources (embedded, or
  /// ACCELVIZ_SHADER_DIR). All or nothing: on ShaderError the old programs stay.
  void reload_shaders();

  /// The matrices render() uses for `view` at this size (clip planes fitted
  /// to content_bounds() unless the view fixes them).
  CameraMatrices matrices(const RenderView& view, int width, int height) const;
  /// Everything uploaded that has a position: mesh, boxes, quads, ray path.
  Aabb content_bounds() const;
  /// The value range the heatmap and its legend use under `view`.
  glm::vec2 heatmap_range(const HeatmapView& view) const;
  /// The heatmap image's smallest and largest value (outside a locked range, some are clamped).
  ValueRange heatmap_values() const { return heatmap_.value_range(); }
  /// Where the legend is drawn for `view` at this size (visible = false when none).
  LegendLayout legend_layout(const RenderView& view, int width, int height) const;

 private:
  struct Programs {
    ShaderProgram mesh, box, colored, heatmap, overlay;
    static Programs build();
  };

  Programs programs_;
  RenderTarget target_;
  MeshPass mesh_;
  BoxPass boxes_;
  BoxPass visited_boxes_;
  ColoredPass ray_geometry_;
  ColoredPass quads_;
  HeatmapPass heatmap_;
  LegendPass legend_;
  std::vector<std::uint32_t> highlighted_;
  std::vector<std::uint32_t> region_prims_;
  glm::vec4 region_color_{1.0f};
  RayPathStyle ray_style_;
  bool has_ray_path_ = false;
};

}  // namespace accelviz
