#pragma once
// Everything that decides how a frame looks, as one plain struct: the
// camera, which layers are on, depth and clip settings, heatmap settings
// and colours. The GUI edits one; `accelviz render` fills one from the
// command line; the renderer draws it the same way in both.
#include "core/scene/scene.h"

#include <glm/glm.hpp>

#include <string>

namespace accelviz {

enum class HeatmapMode {
  off,
  full_screen,  ///< the heatmap replaces the shaded mesh (overlays still drawn, occluded by the mesh's depth)
  blend,        ///< the heatmap over the shaded mesh with `opacity`
};

struct HeatmapView {
  HeatmapMode mode = HeatmapMode::off;
  float opacity = 0.6f;     ///< blend: alpha of the heatmap over the mesh
  bool auto_scale = true;   ///< range [0, image maximum] (1 for an all-zero image), as core's heatmap_scale_max
  float range_min = 0.0f;   ///< fixed range when !auto_scale: value shown as the colour map's start...
  float range_max = 1.0f;   ///< ...and as its end
  bool show_legend = true;  ///< gradient bar, ticks and numbers at the right edge
  std::string title;        ///< legend title; empty: the metric's short name ("nodes")
};

struct RenderView {
  Camera camera;         ///< aspect 0: the image's width/height
  float z_near = 0.0f;   ///< both > 0: fixed clip planes...
  float z_far = 0.0f;    ///< ...else fitted to everything drawn
  int msaa_samples = 1;  ///< 1: none (pixel-exact lines, what tests use); 4 looks better in a window

  glm::vec3 background{0.11f, 0.12f, 0.14f};

  bool show_mesh = true;  ///< scene triangles, headlight flat shading
  glm::vec3 mesh_color{0.75f, 0.76f, 0.78f};
  bool show_wireframe = false;  ///< triangle edges over the mesh
  glm::vec4 wireframe_color{0.05f, 0.05f, 0.06f, 1.0f};

  bool show_boxes = true;           ///< the box list (structure nodes)
  bool boxes_through_mesh = false;  ///< true: boxes are not hidden by the mesh

  bool show_ray_path = true;    ///< the inspected ray: path, hit, normal, visited boxes, tested primitives
  bool ray_path_on_top = true;  ///< path, marker and visited boxes are not hidden by the mesh

  bool show_quads = true;  ///< translucent quads (split planes)

  HeatmapView heatmap;
};

}  // namespace accelviz
