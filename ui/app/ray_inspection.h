#pragma once
// Click to cast: one pixel's primary ray traced with a full VisitTrace (the
// nodes or cells it entered, missed or culled, every primitive test and its
// outcome), plus a shadow ray towards each light of the scene, and the
// step-through replay over the trace. JSON for `dump-ray`.
#include "core/accel/accel.h"
#include "core/scene/scene.h"
#include "ui/app/build_worker.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace accelviz {

struct ShadowRay {
  std::size_t light = 0;  ///< index into Scene::lights
  std::string light_name;
  Ray ray;  ///< from just off the hit towards the light (tmax short of it; inf for directional)
  bool occluded = false;
  RayStats stats;
};

struct RayInspection {
  int x = 0, y = 0;           ///< pixel, row 0 at the top
  int width = 0, height = 0;  ///< of the view it was cast in
  Camera camera;              ///< the view's camera when it was cast (the window's may have moved since)
  std::string structure;      ///< Accelerator::name()
  Ray ray;
  Hit hit;
  RayStats stats;
  VisitTrace trace;
  std::vector<ShadowRay> shadows;  ///< one per light whose side the hit faces; empty on a miss or without lights
};

/// Casts primary_ray(camera, x, y, width, height) through `built` with
/// statistics and a trace, then the shadow rays (any-hit, with statistics).
RayInspection inspect_pixel(const BuiltStructure& built, const Camera& camera, int x, int y, int width, int height,
                            const QueryOptions& query);
/// The same for a given ray (a structure or query change re-casts the ray
/// the user picked, wherever the camera has gone since); pixel fields are
/// left as they are in `like`.
RayInspection inspect_ray(const BuiltStructure& built, const RayInspection& like, const QueryOptions& query);

/// The name of a step kind: "entered", "missed", "culled", "prim-hit", "prim-miss".
const char* step_kind_name(VisitStep::Kind k);

/// What the replay shows after steps [0, upto] (inclusive): the nodes
/// entered so far in order, the primitives tested so far (each once, first
/// test first), and the node of the last node step.
struct ReplayState {
  std::vector<std::uint32_t> entered;
  std::vector<std::uint32_t> tested;
  std::optional<std::uint32_t> current_node;
};
ReplayState replay_upto(const VisitTrace& trace, std::size_t upto);

/// The nodes whose boxes the view draws for the replay at `step`, in order,
/// the last one in the current step's colour: those entered so far, then
/// the current step's node when it was missed or culled, except at the
/// trace's last step, where the last node entered stays the current one (a
/// sibling culled after the hit, drawn last, read as the last box visited).
std::vector<std::uint32_t> replay_box_ids(const VisitTrace& trace, std::size_t step);

/// dump-ray's document: pixel, ray, hit (or null), stats, trace steps with
/// kind/id/t_entry/t_exit (inf written as null), the shadow rays, and the
/// replay position.
nlohmann::json inspection_json(const RayInspection& r, std::size_t replay_step);

}  // namespace accelviz
