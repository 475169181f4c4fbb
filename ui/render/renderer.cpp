#include "ui/render/renderer.h"

#include <string>

namespace accelviz {

Renderer::Programs Renderer::Programs::build() {
  Programs p;
  p.mesh = ShaderProgram::build({"mesh.vert", "mesh.frag"});
  p.box = ShaderProgram::build({"box.vert", "color.frag"});
  p.colored = ShaderProgram::build({"colored.vert", "color.frag"});
  p.heatmap = ShaderProgram::build({"fullscreen.vert", "heatmap.frag"});
  p.overlay = ShaderProgram::build({"overlay2d.vert", "overlay2d.frag"});
  return p;
}

Renderer::Renderer() : programs_(Programs::build()) {
  check_gl_errors("renderer setup");
}

void Renderer::reload_shaders() {
  Programs fresh = Programs::build();  // throws before anything is replaced
  programs_ = std::move(fresh);
}

void Renderer::set_triangles(std::span<const Triangle> triangles) {
  mesh_.upload(triangles);
}

void Renderer::set_triangle_colors(std::span<const glm::vec3> colors) {
  mesh_.upload_colors(colors);
}

void Renderer::set_boxes(std::span<const ColoredBox> boxes) {
  boxes_.upload(boxes);
}

void Renderer::set_quads(std::span<const TranslucentQuad> quads) {
  ColoredGeometry g;
  for (const TranslucentQuad& q : quads) g.add_quad(q);
  quads_.upload(g);
}

void Renderer::set_ray_path(const RayPath& path) {
  ColoredGeometry g;
  for (std::size_t i = 0; i + 1 < path.polyline.size(); ++i) {
    g.add_line(path.polyline[i], path.polyline[i + 1], path.style.path);
  }
  if (path.hit) {
    g.add_line(path.hit_point, path.hit_point + path.normal_length * path.hit_normal, path.style.normal);
    g.points.push_back({path.hit_point, path.style.hit_marker});
  }
  ray_geometry_.upload(g);
  visited_boxes_.upload(fade_boxes(path.visited, path.style.first_visit, path.style.last_visit));
  highlighted_ = path.highlighted;
  ray_style_ = path.style;
  has_ray_path_ = true;
}

void Renderer::set_highlighted_primitives(std::vector<std::uint32_t> prims, glm::vec4 color) {
  region_prims_ = std::move(prims);
  region_color_ = color;
}

void Renderer::clear_ray_path() {
  ray_geometry_.upload({});
  visited_boxes_.upload({});
  highlighted_.clear();
  has_ray_path_ = false;
}

void Renderer::set_heatmap(const MetricImage& image) {
  heatmap_.upload(image);
}

void Renderer::set_colormap(ColorMap map) {
  heatmap_.set_lut(colormap_lut(map));
}

void Renderer::set_colormap_lut(std::span<const glm::vec3> lut) {
  heatmap_.set_lut(lut);
}

Aabb Renderer::content_bounds() const {
  Aabb b = mesh_.bounds();
  b.extend(boxes_.bounds());
  b.extend(quads_.bounds());
  if (has_ray_path_) {
    b.extend(ray_geometry_.bounds());
    b.extend(visited_boxes_.bounds());
  }
  return b;
}

CameraMatrices Renderer::matrices(const RenderView& view, int width, int height) const {
  ClipPlanes clip;
  if (view.z_near > 0.0f && view.z_far > view.z_near) {
    clip = {view.z_near, view.z_far};
  } else {
    clip = fit_clip_planes(view.camera, content_bounds());
  }
  return camera_matrices(view.camera, width, height, clip);
}

glm::vec2 Renderer::heatmap_range(const HeatmapView& view) const {
  if (heatmap_.metric() == HeatMetric::shaded) return {0.0f, 1.0f};  // shading is already in [0, 1]
  if (view.auto_scale) return {0.0f, heatmap_.auto_max()};
  return {view.range_min, view.range_max};
}

LegendLayout Renderer::legend_layout(const RenderView& view, int width, int height) const {
  const HeatmapView& h = view.heatmap;
  if (h.mode == HeatmapMode::off || !h.show_legend || !heatmap_.has_image() ||
      heatmap_.metric() == HeatMetric::shaded) {
    return {};
  }
  const std::string title = h.title.empty() ? std::string(metric_short_label(heatmap_.metric())) : h.title;
  const glm::vec2 range = heatmap_range(h);
  return layout_legend(width, height, range, title, metric_counts(heatmap_.metric()),
                       heatmap_.value_range().max > range.y, heatmap_.value_range().min < range.x);
}

void Renderer::render(const RenderView& view, int width, int height) {
  target_.resize(width, height, view.msaa_samples);
  target_.bind_for_drawing();
  const CameraMatrices m = matrices(view, width, height);

  // Known state, whatever ran before (ImGui leaves scissoring on, for one).
  glDisable(GL_SCISSOR_TEST);
  glDisable(GL_CULL_FACE);
  glDisable(GL_STENCIL_TEST);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glEnable(GL_BLEND);
  // Colour blends by source alpha; destination alpha stays 1, so the frame is
  // opaque and screenshots need no alpha handling.
  glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
  glEnable(GL_PROGRAM_POINT_SIZE);
  glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  glClearColor(view.background.x, view.background.y, view.background.z, 1.0f);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  check_gl_errors("frame setup");

  const HeatmapView& hv = view.heatmap;
  const bool heatmap_on = hv.mode != HeatmapMode::off && heatmap_.has_image();
  const glm::vec2 range = heatmap_range(hv);

  // 1. The surface: shaded mesh, or a full-screen heatmap over the mesh's depth.
  if (heatmap_on && hv.mode == HeatmapMode::full_screen) {
    heatmap_.draw(programs_.heatmap, range, 1.0f);
    if (view.show_mesh) mesh_.draw_depth_only(programs_.mesh, m);
  } else if (view.show_mesh) {
    mesh_.draw_shaded(programs_.mesh, m, glm::vec4(view.mesh_color, 1.0f));
  }
  check_gl_errors("mesh pass");

  if (view.show_wireframe) {
    mesh_.draw_wireframe(programs_.mesh, m, view.wireframe_color);
    check_gl_errors("wireframe pass");
  }

  // 2. Heatmap blended over the shaded mesh, before the overlays so they stay crisp.
  if (heatmap_on && hv.mode == HeatmapMode::blend) {
    heatmap_.draw(programs_.heatmap, range, hv.opacity);
    check_gl_errors("heatmap pass");
  }

  // 2b. Highlighted primitives (a heatmap region's).
  if (view.show_mesh && !region_prims_.empty()) {
    mesh_.draw_primitives(programs_.mesh, m, region_prims_, region_color_);
    check_gl_errors("highlight pass");
  }

  // 3. Box overlays.
  if (view.show_boxes) {
    boxes_.draw(programs_.box, m, !view.boxes_through_mesh);
    check_gl_errors("box pass");
  }

  // 4. The inspected ray: tested primitives on the surface, then visited
  //    boxes, path, normal and hit marker.
  if (view.show_ray_path && has_ray_path_) {
    mesh_.draw_primitives(programs_.mesh, m, highlighted_, ray_style_.highlight);
    visited_boxes_.draw(programs_.box, m, !view.ray_path_on_top);
    ray_geometry_.draw(programs_.colored, m,
                       {.depth_test = !view.ray_path_on_top, .depth_write = true, .point_px = ray_style_.marker_px});
    check_gl_errors("ray path pass");
  }

  // 5. Translucent quads last among world-space layers: no depth writes, so
  //    everything behind them has been drawn and shows through.
  if (view.show_quads) {
    quads_.draw(programs_.colored, m, {.depth_test = true, .depth_write = false});
    check_gl_errors("translucent quad pass");
  }

  // 6. Legend, in screen space.
  const LegendLayout legend = legend_layout(view, width, height);
  if (legend.visible) {
    legend_.draw(programs_.overlay, legend, heatmap_.lut_texture(), width, height);
    check_gl_errors("legend pass");
  }

  target_.resolve();
  glBindVertexArray(0);
  glUseProgram(0);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  check_gl_errors("end of frame");
}

Rgba8Image Renderer::read_pixels() const {
  return target_.read_pixels();
}

void Renderer::present(int window_width, int window_height) const {
  target_.blit_to_default(window_width, window_height);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

}  // namespace accelviz
