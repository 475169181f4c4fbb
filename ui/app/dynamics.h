#pragma once
// The GUI's side of "effects by scene" and of playing a scene's motion,
// GL-free:
//  - force_effect(): the Scene panel's force-on checkboxes, kept in
//    AppConfig::effects; forcing "two-level" also selects the `tlas`
//    structure (what the build worker then builds from the scene's
//    instances);
//  - DynamicsWorker: a SceneAnimator over the app's own copy of the scene and
//    a two-level structure built for it, stepped on a background thread
//    ("latest job wins", ui/app/latest_job_worker.h): the UI thread never
//    builds or refits. Each finished frame's FrameStats is appended to a
//    history the Dynamics panel plots;
//  - DynamicsPlayer: play/pause, scrub, speed: which time the worker is asked
//    to step to next.
// With a structure choice in the request, each frame also carries the
// scene posed at that time (posed_scene()) and the structure over it:
// AppState::show_frame() makes it the one the 3D view, the heatmap and the
// ray inspector use (see docs/dynamics.md). When the choice is `tlas`, the
// animator's structure is built with that choice's options and the frame's
// structure IS the animator's tree after the step (Tlas::snapshot: refitted
// or rebuilt per the rebuild ratio), so the view shows what the plots
// measure; any other structure is built over the pose.
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/scene/animation.h"
#include "core/scene/effects.h"
#include "ui/app/app_config.h"
#include "ui/app/build_worker.h"
#include "ui/app/latest_job_worker.h"

namespace accelviz {

/// Sets (ON) or clears the force of effect NAME in CONFIG.effects. Forcing
/// "two-level" on also sets the structure to "tlas". Returns "" or a one-line
/// error (unknown name, or an effect that cannot be forced).
std::string force_effect(AppConfig& config, const std::string& name, bool on);

/// The effects as JSON: [{name, on, forced, forceable, reason}, ...].
nlohmann::json effects_json(const SceneEffects& effects);

/// The most frames the history keeps (older ones are dropped).
inline constexpr std::size_t kDynamicsHistory = 600;

struct DynamicsRequest {
  std::shared_ptr<const LoadedScene> scene;
  float time = 0.0f;  ///< seconds: the frame to step to
  double rebuild_ratio = 1.3;
  /// The structure the view shows: when set, each stepped frame is also
  /// posed and this structure built over it (DynamicsSnapshot::frame).
  std::optional<StructureChoice> structure;
};

struct DynamicsSnapshot {
  const LoadedScene* scene = nullptr;  ///< which scene the figures are of (identity only)
  std::string spec;
  bool animates = false;
  float duration = 0.0f;     ///< animation_duration(): 0 for procedural motion without channels
  double setup_ms = 0.0;     ///< copy + two-level build before the first frame
  std::uint64_t frames = 0;  ///< frames stepped since the scene was set up (history may hold fewer)
  std::vector<FrameStats> history;
  std::string error;  ///< one line, when set-up or a step failed
  /// The newest frame built for display: the scene posed at frame_time and
  /// the requested structure over it (null before the first, or without a
  /// structure in the requests).
  std::shared_ptr<const BuiltStructure> frame;
  float frame_time = 0.0f;
  double frame_build_ms = 0.0;  ///< posing + building (or, for tlas, snapshotting) that frame's structure
  /// frame's structure is the animator's own tree (the request's structure
  /// is `tlas`), not a build over the posed scene.
  bool frame_is_animator_tree = false;
};

class DynamicsWorker {
 public:
  DynamicsWorker();
  ~DynamicsWorker() = default;  ///< joins the thread (the worker is the last member)
  DynamicsWorker(const DynamicsWorker&) = delete;
  DynamicsWorker& operator=(const DynamicsWorker&) = delete;

  /// Steps the animation of R.scene to R.time (setting up the scene's
  /// structure first when it is a new scene), replacing a queued request.
  /// A request without a scene releases the worker's scene and structure
  /// (latest() becomes null).
  std::uint64_t request(DynamicsRequest r) { return worker_.request(std::move(r)); }
  void cancel() { worker_.cancel(); }
  bool busy() const { return worker_.busy(); }
  std::shared_ptr<const DynamicsSnapshot> latest() const { return worker_.latest(); }

 private:
  struct State;
  std::shared_ptr<State> state_;                                                      ///< worker thread only
  LatestJobWorker<DynamicsRequest, std::shared_ptr<const DynamicsSnapshot>> worker_;  ///< last
};

/// Play/pause, scrub and speed. tick() advances the clock while playing and
/// says whether to ask the worker for the frame at time().
class DynamicsPlayer {
 public:
  bool playing = false;
  float speed = 1.0f;  ///< animation seconds per wall-clock second
  /// Animation seconds a frame wraps at (0: no wrap, procedural motion).
  float duration = 0.0f;

  float time() const { return time_; }
  /// Scrubbing: moves to T (wrapped into the duration) and asks for that frame.
  void seek(float t);
  /// Advances by DT wall seconds while playing; returns true when the frame
  /// at time() should be requested (a new time, and the worker is free).
  bool tick(double dt, bool worker_busy);

 private:
  float time_ = 0.0f;
  float requested_ = -1.0f;
  bool dirty_ = true;
};

}  // namespace accelviz
