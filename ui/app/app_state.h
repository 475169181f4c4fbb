#pragma once
// The app's model, GL-free: settings and the current choice, the scene and
// structure being shown, the build and heatmap workers, the camera, the
// inspected ray and the status line. The GUI main loop calls update() once
// per frame, turns user input into calls here, and draws what it finds;
// scripts drive the same calls, so a scripted run exercises the product.
#include <chrono>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "ui/app/app_config.h"
#include "ui/app/build_worker.h"
#include "ui/app/gpu_heatmap_job.h"
#include "ui/app/heatmap_worker.h"
#include "ui/app/orbit_camera.h"
#include "ui/app/ray_inspection.h"
#include "ui/app/screenshot_files.h"
#include "ui/app/settings.h"

namespace accelviz {

class AppState {
 public:
  /// Starts the workers. Nothing is loaded until open_scene().
  explicit AppState(AppSettings settings, BuildWorker::LoadFn load = {}, BuildWorker::BuildFn build = {});

  AppSettings& settings() { return settings_; }
  const AppSettings& settings() const { return settings_; }
  AppConfig& config() { return settings_.config; }
  const AppConfig& config() const { return settings_.config; }

  // ---- requests -------------------------------------------------------------
  /// Loads `spec` (again, if it is the current scene) and builds the chosen
  /// structure over it in the background; the current scene stays until then.
  void open_scene(const std::string& spec);
  /// Shows SCENE (made in the app: a committed flatten) as a new scene: the
  /// chosen structure is built over it in the background, like open_scene().
  void open_loaded_scene(std::shared_ptr<const LoadedScene> scene);
  /// `set KEY VALUE`: "" or the one-line error (also shown on the status line).
  std::string set_option(std::string_view key, std::string_view value);
  /// Cancels the build in progress (the current structure stays).
  void cancel_build();

  // ---- once per frame ---------------------------------------------------------
  struct FrameUpdate {
    bool scene_changed = false;      ///< a new scene is shown (upload its triangles)
    bool structure_changed = false;  ///< a new structure is shown (re-select boxes)
    bool heatmap_changed = false;    ///< a newer heatmap level is available
  };
  /// Requests a build when the wanted scene/structure differ from the last
  /// request, takes finished builds, requests the heatmap for the current
  /// view (W×H pixels) when anything it depends on changed, and picks up the
  /// newest heatmap level.
  FrameUpdate update(int view_width, int view_height);

  // ---- what is shown -----------------------------------------------------------
  const std::shared_ptr<const BuiltStructure>& current() const { return current_; }
  /// The structure the build worker made over the scene at rest; current()
  /// is it unless a Dynamics frame is shown (show_frame()).
  const std::shared_ptr<const BuiltStructure>& rest() const { return rest_; }
  /// Shows FRAME (the chosen structure built over the scene posed at some
  /// time, DynamicsSnapshot::frame) in place of the rest build, so the 3D
  /// view, the heatmap and the ray inspector show that frame. Accepted only
  /// when REST_SCENE is the rest build's scene and FRAME was built with its
  /// choice (a stale frame of another scene or structure is ignored); a
  /// newer build replaces the frame. Returns whether FRAME is shown.
  bool show_frame(std::shared_ptr<const BuiltStructure> frame, const LoadedScene* rest_scene);
  /// Back to the rest build (no-op when it is shown).
  void show_rest();
  /// A Dynamics frame is shown instead of the rest build.
  bool showing_frame() const { return current_ && current_ != rest_; }
  const Scene* scene() const { return current_ ? &current_->scene->scene : nullptr; }
  /// The scene shown ("" before the first one is ready).
  std::string scene_spec() const { return current_ ? current_->scene->spec : std::string(); }
  /// The scene asked for last (shown in the path field while it loads).
  const std::string& wanted_scene() const { return wanted_scene_; }
  /// open_scene() was called and its outcome (shown or failed) is not in yet.
  bool loading_scene() const { return scene_loading_; }
  const std::shared_ptr<const HeatmapFrame>& heatmap() const { return heatmap_; }
  BuildWorker::Status build_status() const { return builds_.status(); }
  /// The CPU worker or the GPU job is tracing the current view.
  bool heatmap_busy() const { return heatmaps_.busy() || gpu_heatmap_progress().has_value(); }
  /// The CPU heatmap job's share of its rays traced (0 to 1).
  double heatmap_progress() const { return heatmaps_.progress(); }

  /// With a GPU job set (the GUI installs one over its GL context:
  /// app/gui/gpu_heatmap.h) and the View's heatmap-gpu on, the heatmap of a
  /// BVH view is traced by it instead of the CPU worker: update() steps it
  /// once per frame within heatmap-gpu-ms and shows its frame once complete.
  /// Not owned; null removes it.
  void set_gpu_heatmap_tracer(GpuHeatmapJob* job) { gpu_job_ = job; }
  /// Traces the view's heatmap again at the next update, as if something it
  /// shows had changed (e.g. the GPU trace's shader was reloaded).
  void retrace_heatmap() { heatmap_requested_.reset(); }
  /// Why heatmap-gpu is on but the CPU traced the heatmap ("" otherwise).
  const std::string& gpu_heatmap_note() const { return gpu_note_; }
  /// The heatmap shown was traced on the GPU.
  bool heatmap_on_gpu() const { return shown_on_gpu_; }
  /// The GPU trace of the current view in progress, if one is running.
  std::optional<GpuHeatmapJob::Progress> gpu_heatmap_progress() const;
  /// No build queued or running and the heatmap of the current view
  /// complete (what the script's `wait` waits for).
  bool settled() const;

  /// One-line status: the last error (shown in red) or message.
  const std::string& error() const { return error_; }
  const std::string& message() const { return message_; }
  void set_error(std::string e);
  void set_message(std::string m);
  /// Errors reported since the last call, for stderr (each once).
  std::vector<std::string> take_new_errors();

  // ---- camera -------------------------------------------------------------------
  ViewCamera& view_camera() { return camera_; }
  const ViewCamera& view_camera() const { return camera_; }
  Camera camera() const { return camera_.camera(); }
  int view_width() const { return view_w_; }
  int view_height() const { return view_h_; }
  /// R / Home: the scene's default view.
  void reset_camera();
  /// F: frame the selected node (subtree mode) or else the scene, keeping the direction.
  void frame_selection();
  /// A camera of the scene (Scene::cameras index).
  void use_scene_camera(int index);
  /// A `--camera` spec; throws std::invalid_argument for a bad one.
  void set_camera_spec(const std::string& spec);
  /// The surface point under pixel (x, y), if any (double-click pivot).
  std::optional<glm::vec3> pick(int x, int y) const;

  // ---- click to cast --------------------------------------------------------------
  /// Casts pixel (x, y) of the current view; "" or an error message.
  std::string cast_ray(int x, int y);
  const std::optional<RayInspection>& inspection() const { return inspection_; }
  /// Changes whenever the inspection is cast, re-cast or cleared (for redraws).
  std::uint64_t inspection_version() const { return inspection_version_; }
  /// Whether the last change to the inspection was a re-cast of the same ray
  /// (another structure, other query options), not a click.
  bool inspection_recast() const { return inspection_recast_; }
  std::size_t replay_step() const { return replay_step_; }
  /// Moves the replay to `step` (clamped to the trace).
  void set_replay_step(std::size_t step);
  void clear_inspection();

  // ---- reports ----------------------------------------------------------------------
  /// dump-stats' document: scene, structure, options, build figures, the
  /// current view's heatmap figures, status.
  nlohmann::json stats_json() const;
  /// What a screenshot of the current view shows, with the heatmap range drawn.
  ScreenshotInfo screenshot_info(float scale_min, float scale_max) const;

 private:
  // What the view's heatmap shows; a change restarts it.
  struct HeatmapKey {
    const BuiltStructure* structure = nullptr;
    glm::vec3 position{0.0f}, forward{0.0f}, up{0.0f};
    float yfov = 0.0f;
    /// Compared by same_heatmap_image: its threads (and progress) restart nothing.
    HeatmapOptions options;
    bool shadows = false;  ///< shadow rays traced (scene lights or forced on)
    bool gpu = false;      ///< heatmap-gpu
    bool operator==(const HeatmapKey& o) const {
      return structure == o.structure && position == o.position && forward == o.forward && up == o.up &&
             yfov == o.yfov && same_heatmap_image(options, o.options) && shadows == o.shadows && gpu == o.gpu;
    }
  };
  HeatmapKey heatmap_key(int w, int h) const;
  void recast();

  AppSettings settings_;
  BuildWorker builds_;
  HeatmapWorker heatmaps_;

  std::string wanted_scene_;
  bool reload_ = false;
  bool scene_loading_ = false;
  bool follow_effects_ = false;  ///< the next request loads a scene the user opened: its effects choose the level
  /// The single-level structure the app left when an opened scene's
  /// instancing chose `tlas`; a scene without instancing goes back to it.
  /// "" once the user chooses a structure.
  std::string left_for_tlas_;
  std::shared_ptr<const LoadedScene> preloaded_;  ///< open_loaded_scene's scene, until requested
  std::uint64_t scene_request_id_ = 0;            ///< the build request that loads the wanted scene
  std::string requested_scene_;                   ///< of the last build request
  std::optional<StructureChoice> requested_;      ///< of the last build request
  std::uint64_t request_id_ = 0;

  std::shared_ptr<const BuiltStructure> current_;
  std::shared_ptr<const BuiltStructure> rest_;  ///< the last build (current_ unless a frame is shown)
  std::shared_ptr<const HeatmapFrame> heatmap_;
  std::optional<HeatmapKey> heatmap_requested_;
  std::uint64_t heatmap_failure_shown_ = 0;  ///< the failed heatmap job whose error is on the status line
  GpuHeatmapJob* gpu_job_ = nullptr;
  std::string gpu_note_;
  // The current view is traced by gpu_job_; its frame is complete and shown;
  // heatmap_ came from gpu_job_.
  bool heatmap_on_gpu_ = false;
  bool gpu_frame_shown_ = false;
  bool shown_on_gpu_ = false;
  // The full request, for the CPU should the GPU fail mid-trace.
  std::optional<HeatmapRequest> gpu_fallback_;
  std::uint64_t gpu_frame_id_ = 0;
  // When update() last ran and how long its GPU step took (sizes the next budget).
  std::optional<std::chrono::steady_clock::time_point> last_update_;
  double last_gpu_step_ms_ = 0.0;

  ViewCamera camera_;
  int view_w_ = 0, view_h_ = 0;

  std::optional<RayInspection> inspection_;
  QueryOptions inspected_query_;  ///< the query options inspection_ was cast with
  std::size_t replay_step_ = 0;
  std::uint64_t inspection_version_ = 0;
  bool inspection_recast_ = false;

  std::string error_, message_;
  std::vector<std::string> new_errors_;
};

}  // namespace accelviz
