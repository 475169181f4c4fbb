#pragma once
// `accelviz render --view raster`: the overlay view drawn headless through
// OSMesa with the same Renderer the GUI uses (mesh, node boxes, one pixel's
// ray path, heatmap blend), written to PNG.
#include "app/cli_common.h"

#include <nlohmann/json.hpp>

#include <optional>
#include <string>

namespace accelviz::cli {

struct RasterOptions {
  int box_depth = -1;       ///< first depth of node boxes to draw (-1: none)
  int box_depth_last = -1;  ///< last depth (inclusive); -1: same as box_depth
  bool leaves = false;      ///< draw every leaf box instead of a depth
  std::optional<std::pair<int, int>> ray_pixel;  ///< pixel whose primary ray path is drawn
  std::optional<Camera> ray_camera;              ///< the camera that ray is cast from (default: the view's)
  float blend = 0.0f;       ///< heatmap opacity over the mesh (0: no heatmap)
  bool wireframe = false;
};

/// True when this binary was built with the renderer.
bool raster_available();

/// The one-line error of an option (`what`) that needs the renderer in a
/// build without it.
inline std::string needs_renderer(const std::string& what) {
  return what + " needs the renderer, and this build has none (configure with ACCELVIZ_BUILD_UI=ON)";
}

/// Draws the raster view and writes `out`; fills `figures`. Throws on failure.
void render_raster(const Scene& scene, const Accelerator& accel, const Camera& camera, const ImageSize& size,
                   const RasterOptions& ro, const std::string& metric, const std::string& colormap, float fixed_max,
                   const QueryOptions& query, float c_trav, float c_isect, unsigned threads, const std::string& out,
                   bool force, nlohmann::json& figures);

}  // namespace accelviz::cli
