// The GUI main loop: one GLFW window, the renderer drawing the 3D view into
// its framebuffer, Dear ImGui panels on top, the app state polled once per
// frame. Builds and heatmaps run on worker threads, so a frame never waits
// for them; scripts are run between frames through the same calls as the
// mouse and keyboard.
#include "app/cli_common.h"
#include "app/gui/gpu_heatmap.h"
#include "app/gui/gui.h"
#include "app/gui/insight_views.h"
#include "app/gui/scene_view.h"
#include "core/accel/tlas/tlas.h"
#include "core/scene/load.h"
#include "core/util/huge_page_allocator.h"
#include "core/util/json_text.h"
#include "ui/app/app_state.h"
#include "ui/app/dynamics.h"
#include "ui/app/flatten_worker.h"
#include "ui/app/script.h"
#include "ui/app/settings.h"
#include "ui/app/sweep_worker.h"
#include "ui/gl/glfw_context.h"
#include "ui/gl/shader.h"
#include "ui/imgui/imgui_context.h"
#include "ui/panels/panels.h"
#include "ui/render/screenshot.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <memory>
#include <vector>

namespace accelviz {
namespace {

using Clock = std::chrono::steady_clock;

// SIGTERM, SIGHUP (a logout) and SIGINT ask the window to close as its close button does, so the
// settings and layout are saved on the way out (a kill skipped that: the changes since the last
// scene opened were lost). The main loop wakes at least every 0.25 s and sees the flag. A signal
// repeated is the same request (`timeout` sends SIGTERM to the program and then to its process
// group: a handler reset on the first let the second end the program before the saves); SIGKILL
// ends it at once.
volatile std::sig_atomic_t g_quit_signal = 0;

extern "C" void on_quit_signal(int sig) {
  g_quit_signal = sig;
}

void catch_quit_signals() {
  struct sigaction sa {};
  sa.sa_handler = &on_quit_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  for (const int sig : {SIGTERM, SIGHUP, SIGINT}) sigaction(sig, &sa, nullptr);
}

// A background job's snapshot (sweep, robustness lab: their State enums share these four names).
template <class State>
const char* job_state_name(State s) {
  static const char* const names[] = {"running", "done", "cancelled", "failed"};
  return names[static_cast<int>(s)];
}

/// Job `id` (or a newer one) has published its last snapshot: done, cancelled or failed.
template <class Snapshot>
bool job_ended(const Snapshot* s, std::uint64_t id) {
  return s && s->id >= id && s->state != Snapshot::State::running;
}

// Dropped file names arrive in a GLFW callback; they are queued here and
// opened by the main loop (one window, so one queue).
std::vector<std::string>* g_dropped = nullptr;

void on_drop(GLFWwindow* /*window*/, int count, const char** paths) {
  if (!g_dropped) return;
  for (int i = 0; i < count; ++i) g_dropped->emplace_back(paths[i]);
}

// Key presses as events. ImGui 1.86 keeps only key *state* (io.KeysDown),
// so a press and release that arrive in the same poll (a quick tap during
// a slow frame) would never be seen as pressed; GLFW's callback sees every
// one. ImGui's backend chains to this callback (installed before it).
struct KeyPress {
  int key;
  int mods;
};
std::vector<KeyPress>* g_keys = nullptr;

void on_key(GLFWwindow* /*window*/, int key, int /*scancode*/, int action, int mods) {
  if (g_keys && (action == GLFW_PRESS || action == GLFW_REPEAT))
    g_keys->push_back({key, mods | (action == GLFW_REPEAT ? 0x10000 : 0)});
}

class Gui final : public ScriptHost {
 public:
  explicit Gui(const GuiOptions& options, AppSettings settings, std::optional<ScriptRunner> script,
               std::string settings_error);
  ~Gui() override;
  int run();
  Status execute(const ScriptCommand& command) override;
  /// The script opens its own scene first: load nothing before it.
  void skip_initial_open() { skip_initial_open_ = true; }

 private:
  void handle_input(int fbw, int fbh, int ww, int wh);
  void draw_panels(const panels::PanelLayout& layout);
  /// The effects of the shown scene under the user's forces (recomputed when either changes).
  const SceneEffects* effects();
  /// The visit count at the top of the 3D boxes' colour ramp while they are
  /// shown and coloured by visits (the Tree's swatches then share it).
  std::optional<std::uint64_t> box_ramp_max() const;
  /// Uploads the overlay as the settings and the insight stand now (before a
  /// screenshot or a dump reads it, rather than as of the last frame).
  void sync_overlay();
  /// The Dynamics panel: the timeline and per-frame figures while per-frame updates are on.
  void draw_dynamics(const panels::PanelLayout& layout);
  /// The Flatten what-if panel while the structure is tlas; takes a finished commit.
  void draw_flatten(const panels::PanelLayout& layout);
  /// Asks the flatten worker to predict or commit IDS on the shown scene and view.
  std::uint64_t request_flatten(FlattenRequest::Kind kind, std::vector<std::uint32_t> ids);
  /// A finished commit (once): its merged scene is opened and built.
  void take_flatten_commit();
  /// The Cost of accuracy panel's Run: a sweep of accuracy_.params over the
  /// shown scene, structure and view; its id, or none with accuracy_.error set.
  std::optional<std::uint64_t> request_sweep();
  /// The Robustness panel's Run over the shown scene (and structure, when the
  /// panel's box says so); its id, or none when no scene is shown.
  std::optional<std::uint64_t> request_robustness();
  /// Keeps the worker's latest result when it is a prediction (flatten_prediction_).
  void note_flatten_prediction();
  /// The spec of the scene `r` was computed on when that is the flatten panel's scene, else "".
  std::string flatten_spec_of(const FlattenResult& r) const;
  void take_screenshot();
  /// Rebuilds the shader programs (from `dir` when given: it becomes the
  /// override folder). Returns "" or the one-line error; the old programs stay on error.
  std::string reload_shaders(const std::optional<std::string>& dir = std::nullopt);
  SavedScreenshot write_frame(const std::optional<std::filesystem::path>& explicit_path);
  void report_errors();
  void save_settings_now();
  std::string redraw_key(int fbw, int fbh) const;

  GuiOptions options_;
  std::filesystem::path config_dir_;
  AppState app_;
  // GL objects die before the window that owns their context.
  std::unique_ptr<GlfwContext> window_;
  std::unique_ptr<ImGuiContextGuard> imgui_;
  std::unique_ptr<SceneView> view_;
  std::unique_ptr<GpuHeatmap> gpu_heatmap_;  ///< View panel "Trace on: GPU" (window's context)
  std::optional<ScriptRunner> script_;
  SweepWorker sweeps_;  ///< the Cost of accuracy panel's sweeps
  panels::AccuracyPanelState accuracy_;
  InsightViews insight_;         ///< A/B, predicted vs measured, SAH explainer, tree, scenarios
  RobustnessWorker robustness_;  ///< the Robustness panel's lab runs
  panels::RobustnessPanelState robustness_panel_;
  DynamicsWorker dynamics_;  ///< steps the shown scene's animation off the UI thread
  DynamicsPlayer player_;
  FlattenWorker flatten_;  ///< the Flatten what-if's predictions and commits, off the UI thread
  panels::FlattenPanelState flatten_panel_;
  std::shared_ptr<const LoadedScene> flatten_scene_;  ///< the scene the selection is of (held: addresses come back)
  std::uint64_t flatten_taken_ = 0;                   ///< the last commit result acted on
  /// The last prediction finished and its scene's spec: what dump-flatten
  /// writes, also after a commit has replaced it as the worker's latest.
  std::shared_ptr<const FlattenResult> flatten_prediction_;
  std::string flatten_prediction_spec_;
  std::optional<std::uint64_t> flatten_wait_;         ///< script flatten / flatten-commit: the job waited for
  std::optional<std::uint64_t> sweep_wait_;           ///< script sweep: its request, which dump-sweep waits for
  nlohmann::json sweep_context_;                      ///< script sweep: the scene, view and options it started from
  std::optional<std::uint64_t> lab_wait_;  ///< script robustness: its request, which dump-robustness waits for
  std::optional<SceneEffects> effects_;
  std::shared_ptr<const LoadedScene> effects_scene_;  ///< held: a freed scene's address may come back
  EffectForces effects_forces_;
  std::shared_ptr<const LoadedScene> dynamics_scene_;    ///< the scene the player was reset for
  std::shared_ptr<const BuiltStructure> dynamics_rest_;  ///< the build the shown frames are made for
  Clock::time_point dynamics_clock_ = Clock::now();
  std::optional<std::uint64_t> play_target_;    ///< script `play`: the frame count to reach
  std::uint64_t frames_drawn_ = 0;              ///< frames swapped so far (dump-stats `frames`)
  std::optional<std::uint64_t> frames_target_;  ///< script `frames`: the frame count to reach
  std::vector<std::string> dropped_;
  std::vector<KeyPress> keys_;

  std::string path_field_;
  std::string last_screenshot_;
  std::string last_title_;
  std::string last_redraw_key_;
  bool show_help_ = false;
  bool press_in_view_ = false;
  bool quit_ = false;
  int exit_code_ = 0;
  bool size_pending_ = false;
  int size_frames_ = 0;
  std::string initial_scene_;
  bool fallback_tried_ = false;
  bool skip_initial_open_ = false;
  bool was_busy_ = true;
  Clock::time_point start_ = Clock::now();
};

Gui::Gui(const GuiOptions& options, AppSettings settings, std::optional<ScriptRunner> script,
         std::string settings_error)
    : options_(options), config_dir_(config_dir()), app_(std::move(settings)), script_(std::move(script)) {
  WindowOptions wo;
  wo.width = app_.settings().window_width;
  wo.height = app_.settings().window_height;
  wo.title = "accelviz";
  wo.vsync = true;
  try {
    window_ = std::make_unique<GlfwContext>(wo);
  } catch (const std::exception& e) {
    throw NoWindow(e.what());
  }
  g_dropped = &dropped_;
  g_keys = &keys_;
  glfwSetDropCallback(window_->window(), on_drop);
  glfwSetKeyCallback(window_->window(), on_key);  // before ImGui's, which chains to it
  imgui_ = std::make_unique<ImGuiContextGuard>(
      window_->window(),
      options_.use_settings ? std::optional<std::filesystem::path>(imgui_ini_file(config_dir_)) : std::nullopt);
  view_ = std::make_unique<SceneView>();
  gpu_heatmap_ = std::make_unique<GpuHeatmap>();
  // Stepped from app_.update() on this thread, with the window's context current.
  app_.set_gpu_heatmap_tracer(gpu_heatmap_.get());
  if (!settings_error.empty()) app_.set_error(settings_error);
  if (!imgui_->load_problem().empty()) app_.set_error(imgui_->load_problem());
}

Gui::~Gui() {
  g_dropped = nullptr;
  g_keys = nullptr;
  // Renderer and ImGui objects need the window's context current when they die.
  if (window_) window_->make_current();
  app_.set_gpu_heatmap_tracer(nullptr);
  gpu_heatmap_.reset();
  view_.reset();
  imgui_.reset();
}

void Gui::report_errors() {
  for (const std::string& e : app_.take_new_errors()) std::fprintf(stderr, "accelviz: %s\n", e.c_str());
}

void Gui::save_settings_now() {
  if (!options_.use_settings || !options_.save_settings) return;
  int w = 0, h = 0;
  glfwGetWindowSize(window_->window(), &w, &h);
  if (w >= 100 && h >= 100) {
    app_.settings().window_width = w;
    app_.settings().window_height = h;
  }
  if (const std::string e = save_settings(settings_file(config_dir_), app_.settings()); !e.empty()) app_.set_error(e);
}

std::string Gui::redraw_key(int fbw, int fbh) const {
  const Camera c = app_.camera();
  std::string key = std::to_string(fbw) + "x" + std::to_string(fbh);
  for (float f : {c.position.x, c.position.y, c.position.z, c.forward.x, c.forward.y, c.forward.z, c.up.x, c.up.y,
                  c.up.z, c.yfov})
    (key += ',') += std::to_string(f);
  for (const auto& [k, v] : option_values(app_.config())) (((key += k) += '=') += v) += ';';
  return key;
}

void Gui::handle_input(int fbw, int fbh, int ww, int wh) {
  ImGuiIO& io = ImGui::GetIO();
  // ImGui works in window coordinates; the view and its rays in framebuffer
  // pixels (more of them on HiDPI displays).
  const float sx = ww > 0 ? static_cast<float>(fbw) / static_cast<float>(ww) : 1.0f;
  const float sy = wh > 0 ? static_cast<float>(fbh) / static_cast<float>(wh) : 1.0f;
  const int px = static_cast<int>(std::floor(io.MousePos.x * sx));
  const int py = static_cast<int>(std::floor(io.MousePos.y * sy));
  const bool over_view = ImGui::IsMousePosValid() && px >= 0 && py >= 0 && px < fbw && py < fbh;
  ViewCamera& cam = app_.view_camera();

  if (ImGui::IsMouseClicked(ImGuiMouseButton_Left)) press_in_view_ = !io.WantCaptureMouse && over_view;
  if (!io.WantCaptureMouse) {
    const ImVec2 d = io.MouseDelta;
    const bool moved = d.x != 0.0f || d.y != 0.0f;
    // Ctrl+drag: select a region of the view's rays (insight: nodes and primitives they touched).
    if (press_in_view_ && io.KeyCtrl && ImGui::IsMouseDragging(ImGuiMouseButton_Left)) {
      const ImVec2 o = io.MouseClickedPos[ImGuiMouseButton_Left];
      ImGui::GetForegroundDrawList()->AddRect(o, io.MousePos, IM_COL32(255, 255, 255, 255), 0.0f, 0, 1.5f);
    } else if (press_in_view_ && ImGui::IsMouseDragging(ImGuiMouseButton_Left) && moved) {
      cam.unfix();
      if (io.KeyShift)
        cam.orbit.pan(d.x * sx, d.y * sy, fbh);
      else
        cam.orbit.orbit(d.x, d.y);
    }
    if ((ImGui::IsMouseDragging(ImGuiMouseButton_Right) || ImGui::IsMouseDragging(ImGuiMouseButton_Middle)) && moved) {
      cam.unfix();
      cam.orbit.pan(d.x * sx, d.y * sy, fbh);
    }
    if (io.MouseWheel != 0.0f && over_view) {
      cam.unfix();
      cam.orbit.zoom(io.MouseWheel);
    }
    if (ImGui::IsMouseDoubleClicked(ImGuiMouseButton_Left) && over_view) {
      if (const auto p = app_.pick(px, py)) {
        cam.unfix();
        cam.orbit.set_pivot(*p);
      }
    } else if (ImGui::IsMouseReleased(ImGuiMouseButton_Left) && press_in_view_ && io.KeyCtrl &&
               io.MouseDragMaxDistanceSqr[ImGuiMouseButton_Left] >= io.MouseDragThreshold * io.MouseDragThreshold) {
      const ImVec2 o = io.MouseClickedPos[ImGuiMouseButton_Left];
      insight_.select_view_region(app_, static_cast<int>(std::floor(o.x * sx)), static_cast<int>(std::floor(o.y * sy)),
                                  px, py);
    } else if (ImGui::IsMouseReleased(ImGuiMouseButton_Left) && press_in_view_ && over_view &&
               io.MouseDragMaxDistanceSqr[ImGuiMouseButton_Left] < io.MouseDragThreshold * io.MouseDragThreshold) {
      if (const std::string e = app_.cast_ray(px, py); !e.empty()) app_.set_error(e);
    }
    // The heatmap pixel under the mouse, while nothing is being dragged.
    const auto& frame = app_.heatmap();
    if (over_view && frame && app_.config().view.heatmap != HeatmapDisplay::off && !ImGui::IsAnyMouseDown() &&
        frame->image.width > 0) {
      const int fx = std::min(frame->image.width - 1, px * frame->image.width / fbw);
      const int fy = std::min(frame->image.height - 1, py * frame->image.height / fbh);
      panels::pixel_tooltip(fx, fy, frame->at(fx, fy), frame->image.metric, frame->complete,
                            frame->request.structure ? frame->request.structure->choice.name : std::string());
    }
  }

  std::vector<KeyPress> keys;
  keys.swap(keys_);
  for (const KeyPress& k : keys) {
    const bool repeat = (k.mods & 0x10000) != 0;
    const bool ctrl = (k.mods & GLFW_MOD_CONTROL) != 0;
    // Ctrl+Q quits even while a text field has the keyboard.
    if (ctrl && k.key == GLFW_KEY_Q) quit_ = true;
    if (io.WantCaptureKeyboard || ctrl) continue;
    switch (k.key) {
      case GLFW_KEY_LEFT:
        if (app_.inspection() && app_.replay_step() > 0) app_.set_replay_step(app_.replay_step() - 1);
        break;
      case GLFW_KEY_RIGHT:
        if (app_.inspection()) app_.set_replay_step(app_.replay_step() + 1);
        break;
      default:
        if (repeat) break;  // only the arrows repeat
        if (k.key == GLFW_KEY_F) app_.frame_selection();
        if (k.key == GLFW_KEY_R || k.key == GLFW_KEY_HOME) app_.reset_camera();
        if (k.key == GLFW_KEY_F5) {
          if (const std::string err = reload_shaders(); !err.empty()) app_.set_error(err);
        }
        if (k.key == GLFW_KEY_F12) take_screenshot();
        if (k.key == GLFW_KEY_H || k.key == GLFW_KEY_F1) show_help_ = !show_help_;
    }
  }
}

void Gui::draw_panels(const panels::PanelLayout& layout) {
  const panels::SceneAction sa = panels::scene_panel(path_field_, app_.settings().recent, app_.scene(),
                                                     app_.scene_spec(), app_.view_camera().scene_camera, layout);
  if (sa.open) app_.open_scene(*sa.open);
  if (sa.camera) app_.use_scene_camera(*sa.camera);
  if (sa.reset_view) app_.reset_camera();
  if (const auto force = panels::scene_effects_section(effects())) {
    const std::string err = force_effect(app_.config(), force->first, force->second);
    if (!err.empty()) app_.set_error(err);
  }
  draw_dynamics(layout);
  draw_flatten(layout);

  const BuildWorker::Status st = app_.build_status();
  panels::BuildProgress bp;
  bp.busy = st.busy;
  bp.fraction = st.fraction;
  bp.stage = st.stage;
  if (app_.current()) bp.shown = describe_structure(app_.current()->choice);
  bool cancel = false;
  panels::structure_panel(app_.config().structure, bp, cancel, layout);
  if (cancel) app_.cancel_build();

  panels::stats_panel(app_.current().get(), app_.heatmap().get(), layout);

  panels::ViewInfo vi;
  if (const BuiltStructure* b = app_.current().get()) {
    vi.node_kind = b->nodes.kind();
    vi.structure = b->accel->name();
    if (!b->accel->inspectable()) vi.uncounted = b->accel->name();
    vi.max_depth = b->nodes.max_depth();
    vi.node_count = b->nodes.size();
    if (const auto* tlas = dynamic_cast<const Tlas*>(b->accel.get())) {
      vi.blas_max_depth = blas_max_depth(*tlas);
      vi.instances = tlas->instances().size();
    }
  }
  vi.boxes_drawn = view_->boxes_drawn();
  vi.boxes_truncated = view_->boxes_truncated();
  vi.boxes_matched = view_->boxes_matched();
  const glm::vec2 range = view_->heatmap_range(app_);
  vi.range_min = range.x;
  vi.range_max = range.y;
  const ValueRange values = view_->heatmap_values();
  vi.value_min = values.min;
  vi.value_max = values.max;
  vi.heatmap_on_gpu = app_.heatmap_on_gpu();
  vi.gpu_note = app_.gpu_heatmap_note();
  const auto gpu_trace = app_.gpu_heatmap_progress();
  if (gpu_trace) {
    vi.gpu_rows_done = gpu_trace->rows_done;
    vi.gpu_rows = gpu_trace->rows;
  }
  vi.box_node_note = insight_.box_node_note(app_);
  panels::view_panel(app_.config().view, vi, layout, &app_.config().structure.query);

  const auto& insp = app_.inspection();
  if (const auto step = panels::ray_panel(insp ? &*insp : nullptr, app_.replay_step(),
                                          app_.current() ? &app_.current()->nodes : nullptr, layout))
    app_.set_replay_step(*step);

  if (panels::screenshot_panel(app_.settings().screenshot_dir, default_screenshot_dir().string(), last_screenshot_,
                               layout))
    take_screenshot();
  panels::help_panel(show_help_, layout);
  std::string heatmap_status;
  if (gpu_trace)
    heatmap_status = "tracing heatmap on the GPU: " +
                     std::to_string(gpu_trace->rows > 0 ? 100 * gpu_trace->rows_done / gpu_trace->rows : 0) + "%";
  else if (app_.heatmap_busy())
    heatmap_status = "refining heatmap: " + std::to_string(static_cast<int>(100.0 * app_.heatmap_progress())) + "%";
  panels::status_bar(app_.message(), app_.error(), bp, heatmap_status, layout);

  const std::shared_ptr<const SweepSnapshot> sweep = sweeps_.latest();
  const panels::AccuracyAction aa =
      panels::accuracy_panel(accuracy_, sweep.get(), sweeps_.busy(), app_.config().structure.name, layout);
  if (aa.cancel) sweeps_.cancel();
  if (aa.run) (void)request_sweep();
  if (aa.apply) {
    const std::string err = apply_sweep_point(app_.config().structure, aa.apply_structure, *aa.apply);
    if (err.empty())
      app_.set_message("applied " + aa.apply_structure + " " + setting_label(*aa.apply) + " from the sweep");
    else
      app_.set_error(err);
  }
  insight_.draw(app_, layout, box_ramp_max());
  view_->set_box_insight(insight_.box_insight(app_));

  const std::shared_ptr<const RobustnessSnapshot> lab = robustness_.latest();
  const panels::RobustnessAction ra =
      panels::robustness_panel(robustness_panel_, lab.get(), robustness_.busy(), app_.config().structure.name, layout);
  if (ra.cancel) robustness_.cancel();
  if (ra.run && !request_robustness()) app_.set_error("robustness: no scene shown yet");
}

std::optional<std::uint64_t> Gui::request_robustness() {
  if (!app_.current()) return std::nullopt;
  RobustnessRequest r;
  r.scene = app_.current()->scene;
  r.options.rays = static_cast<std::size_t>(robustness_panel_.rays);
  const std::string& shown = app_.config().structure.name;
  r.options.structure = robustness_panel_.with_structure && lab_times_own_traversal(shown) ? shown : "";
  return robustness_.request(std::move(r));
}

void Gui::sync_overlay() {
  view_->set_box_insight(insight_.box_insight(app_));
  view_->sync(app_);
}

std::optional<std::uint64_t> Gui::box_ramp_max() const {
  if (!app_.config().view.show_boxes || !view_->boxes_by_visits()) return std::nullopt;
  return view_->boxes_visit_max();
}

const SceneEffects* Gui::effects() {
  if (!app_.rest()) return nullptr;
  const std::shared_ptr<const LoadedScene>& scene = app_.rest()->scene;  // at rest: a shown frame is a copy
  const EffectForces& f = app_.config().effects;
  const bool same_forces = f.shadow_rays == effects_forces_.shadow_rays &&
                           f.per_frame_updates == effects_forces_.per_frame_updates &&
                           f.two_level == effects_forces_.two_level && f.textures == effects_forces_.textures;
  if (!effects_ || scene != effects_scene_ || !same_forces) {
    effects_ = decide_effects(scene->scene, f);
    effects_scene_ = scene;
    effects_forces_ = f;
  }
  return &*effects_;
}

void Gui::draw_dynamics(const panels::PanelLayout& layout) {
  const auto now = Clock::now();
  const double dt = std::chrono::duration<double>(now - dynamics_clock_).count();
  dynamics_clock_ = now;
  const SceneEffects* fx = effects();
  const std::shared_ptr<const BuiltStructure>& cur = app_.rest();
  if (!fx || !cur || !fx->per_frame_updates.on) {
    if (dynamics_scene_) dynamics_.request({});  // releases the worker's copy of the structure
    dynamics_scene_.reset();
    dynamics_rest_.reset();
    player_.playing = false;
    app_.show_rest();
    return;
  }
  if (dynamics_scene_ != cur->scene) {  // a new scene: the timeline starts over
    dynamics_scene_ = cur->scene;
    player_ = DynamicsPlayer{};
    player_.duration = animation_duration(cur->scene->scene);
    player_.seek(0.0f);
  }
  if (dynamics_rest_ != cur) {  // a new build (another structure): pose the current time with it
    dynamics_rest_ = cur;
    player_.seek(player_.time());
  }
  if (player_.tick(dt, dynamics_.busy())) {
    DynamicsRequest r;
    r.scene = cur->scene;
    r.time = player_.time();
    r.structure = cur->choice;  // the view shows this frame (latest frame wins)
    dynamics_.request(std::move(r));
  }
  std::shared_ptr<const DynamicsSnapshot> snap = dynamics_.latest();
  if (snap && snap->scene != cur->scene.get()) snap.reset();
  if (snap && snap->frame) app_.show_frame(snap->frame, snap->scene);  // refused when of another build
  panels::dynamics_panel(player_, snap.get(), dynamics_.busy(), layout);
}

SavedScreenshot Gui::write_frame(const std::optional<std::filesystem::path>& explicit_path) {
  // Draw the current state now, so the file is exactly what the view shows
  // after this frame's changes (uploads included).
  const int w = window_->width(), h = window_->height();
  sync_overlay();
  view_->draw(app_, w, h);
  const RgbImage frame = to_rgb(view_->renderer().read_pixels());
  const glm::vec2 range = view_->heatmap_range(app_);
  ScreenshotInfo info = app_.screenshot_info(range.x, range.y);
  info.program = cli::program_json();
  info.boxes_drawn = view_->boxes_drawn();
  info.boxes_matched = view_->boxes_matched();
  if (app_.config().view.show_boxes) {
    info.box_node_note = insight_.box_node_note(app_);
    info.boxes_of_region = view_->boxes_of_region();
    info.boxes_by_visits = view_->boxes_by_visits();
  }
  if (explicit_path) return save_screenshot_as(*explicit_path, frame, info);
  const std::filesystem::path dir = app_.settings().screenshot_dir.empty()
                                        ? default_screenshot_dir()
                                        : std::filesystem::path(app_.settings().screenshot_dir);
  return save_screenshot(dir, frame, info, std::time(nullptr));
}

std::string Gui::reload_shaders(const std::optional<std::string>& dir) {
  if (dir) {
    std::error_code ec;
    if (!std::filesystem::is_directory(*dir, ec)) return "reload-shaders: " + *dir + ": not a folder";
    set_shader_dir(*dir);
  }
  try {
    // Everything is built before anything is replaced: the GPU heatmap's
    // trace (when one has been made) and the 3D view's programs.
    std::unique_ptr<GpuBvhTracer> tracer = gpu_heatmap_ ? gpu_heatmap_->fresh_tracer() : nullptr;
    view_->renderer().reload_shaders();
    if (tracer) {
      gpu_heatmap_->replace_tracer(std::move(tracer));
      app_.retrace_heatmap();
    }
  } catch (const std::exception& e) {
    return std::string("shaders not reloaded: ") + e.what();
  }
  const std::string from = shader_dir();
  app_.set_message(from.empty() ? "shaders reloaded (built-in)"
                                : "shaders reloaded (files in " + from + " over the built-in ones)");
  return "";
}

void Gui::take_screenshot() {
  const SavedScreenshot r = write_frame(std::nullopt);
  if (r.ok) {
    last_screenshot_ = r.png.string();
    app_.set_message("screenshot written: " + r.png.string() + " (+ .json)");
    if (!options_.quiet) std::printf("%s\n", r.png.string().c_str());
  } else {
    app_.set_error("screenshot: " + r.error);
  }
}

std::string Gui::flatten_spec_of(const FlattenResult& r) const {
  return flatten_scene_ && r.scene == flatten_scene_.get() ? flatten_scene_->spec : std::string();
}

void Gui::note_flatten_prediction() {
  const std::shared_ptr<const FlattenResult> r = flatten_.latest();
  if (!r || r->kind != FlattenRequest::Kind::preview || r == flatten_prediction_) return;
  flatten_prediction_ = r;
  flatten_prediction_spec_ = flatten_spec_of(*r);
}

std::optional<std::uint64_t> Gui::request_sweep() {
  accuracy_.error.clear();
  try {
    if (!app_.current()) throw std::invalid_argument("no scene shown yet");
    SweepRequest r;
    r.scene = app_.current()->scene;
    r.structure = app_.config().structure.name;
    r.base = app_.config().structure.options;
    r.query = app_.config().structure.query;
    r.params = parse_sweep_params_text(r.structure, accuracy_.params);
    r.camera = app_.camera();
    r.width = accuracy_.width;
    r.height = accuracy_.height;
    r.repeat = accuracy_.repeat;
    r.calibrate = accuracy_.calibrate;
    return sweeps_.request(std::move(r));
  } catch (const std::exception& e) {
    accuracy_.error = e.what();
    return std::nullopt;
  }
}

void Gui::take_flatten_commit() {
  const std::shared_ptr<const FlattenResult> r = flatten_.latest();
  if (!r || r->id <= flatten_taken_ || r->kind != FlattenRequest::Kind::commit) return;
  flatten_taken_ = r->id;
  if (!r->error.empty())
    app_.set_error(r->error);
  else if (r->committed)
    app_.open_loaded_scene(r->committed);
}

std::uint64_t Gui::request_flatten(FlattenRequest::Kind kind, std::vector<std::uint32_t> ids) {
  FlattenRequest r;
  r.kind = kind;
  r.scene = app_.rest()->scene;
  r.instances = std::move(ids);
  r.camera = app_.camera();
  r.width = flatten_panel_.width;
  r.height = flatten_panel_.height;
  r.options.blas = app_.config().structure.options.bvh;  // as the factory builds "tlas"
  r.options.blas.compute_epo = false;
  if (r.options.blas.threads == 0) r.options.blas.threads = app_.config().structure.options.threads;
  r.options.tlas = r.options.blas;
  return flatten_.request(std::move(r));
}

void Gui::draw_flatten(const panels::PanelLayout& layout) {
  note_flatten_prediction();
  take_flatten_commit();
  const std::shared_ptr<const BuiltStructure>& rest = app_.rest();
  if (!rest || !rest->accel || rest->accel->name() != "tlas") return;
  if (flatten_scene_ != rest->scene) {  // another scene: the selection starts over
    flatten_scene_ = rest->scene;
    flatten_panel_.scene_identity = flatten_scene_.get();
    panels::set_flatten_selection(flatten_panel_, {});
  }
  std::optional<std::uint32_t> clicked;
  if (const auto& insp = app_.inspection(); insp && insp->hit.valid() && insp->hit.instance != kInvalidId)
    clicked = insp->hit.instance;
  const std::shared_ptr<const FlattenResult> result = flatten_.latest();
  const panels::FlattenAction a = panels::flatten_panel(flatten_panel_, &flatten_scene_->scene, result.get(),
                                                        flatten_.busy(), flatten_.fraction(), clicked, layout);
  if (a.cancel) flatten_.cancel();
  if (a.preview) request_flatten(FlattenRequest::Kind::preview, flatten_panel_.selected);
  if (a.commit) request_flatten(FlattenRequest::Kind::commit, flatten_panel_.selected);
}

ScriptHost::Status Gui::execute(const ScriptCommand& c) {
  using K = ScriptCommand::Kind;
  auto fail_if = [](const std::string& error) {
    if (!error.empty()) throw std::runtime_error(error);
  };
  switch (c.kind) {
    case K::open:
      path_field_ = c.arg;
      app_.open_scene(c.arg);
      return Status::done;
    case K::structure:
      fail_if(app_.set_option("structure", c.arg));
      return Status::done;
    case K::set:
      // A node id names a node of one build: it waits for the build on its
      // way (a `structure` just before) and is that build's.
      if (c.arg == "box-node" && !app_.settled()) return Status::again;
      fail_if(app_.set_option(c.arg, c.value));
      if (c.arg == "box-node") insight_.box_node_set_again(app_);
      return Status::done;
    case K::camera:
      // After `open`, the camera applies to the new scene: wait for it
      // (its arrival resets the view to the scene's default).
      if (app_.loading_scene()) return Status::again;
      app_.set_camera_spec(c.arg);
      return Status::done;
    case K::size: {
      int w = 0, h = 0;
      glfwGetWindowSize(window_->window(), &w, &h);
      if (w == c.x && h == c.y) {
        size_pending_ = false;
        return Status::done;
      }
      if (!size_pending_) {
        glfwSetWindowSize(window_->window(), c.x, c.y);
        size_pending_ = true;
        size_frames_ = 0;
      } else if (++size_frames_ > 600) {
        size_pending_ = false;
        throw std::runtime_error("the window stayed " + std::to_string(w) + "x" + std::to_string(h));
      }
      return Status::again;
    }
    case K::wait:
      return app_.settled() && insight_.caught_up(app_) ? Status::done : Status::again;
    case K::click:
      fail_if(app_.cast_ray(c.x, c.y));
      return Status::done;
    case K::step: {
      const auto& insp = app_.inspection();
      if (!insp) throw std::runtime_error("no ray cast yet (use click first)");
      const std::size_t n = insp->trace.steps.size();
      const std::size_t cur = app_.replay_step();
      if (c.arg == "next")
        app_.set_replay_step(cur + 1);
      else if (c.arg == "prev")
        app_.set_replay_step(cur > 0 ? cur - 1 : 0);
      else if (c.arg == "first")
        app_.set_replay_step(0);
      else if (c.arg == "last")
        app_.set_replay_step(n > 0 ? n - 1 : 0);
      else {
        const std::size_t k = std::stoul(c.arg);
        if (k >= n) throw std::runtime_error("step " + c.arg + ": the trace has " + std::to_string(n) + " steps");
        app_.set_replay_step(k);
      }
      return Status::done;
    }
    case K::screenshot: {
      const SavedScreenshot r = write_frame(std::filesystem::path(c.arg));
      if (!r.ok) throw std::runtime_error(r.error);
      last_screenshot_ = r.png.string();
      app_.set_message("screenshot written: " + r.png.string() + " (+ .json)");  // as the button and F12 say
      if (!options_.quiet) std::printf("%s\n", r.png.string().c_str());
      return Status::done;
    }
    case K::reload_shaders: {
      const std::string err = reload_shaders(c.arg.empty() ? std::nullopt : std::optional<std::string>(c.arg));
      if (!err.empty()) throw std::runtime_error(err);
      return Status::done;
    }
    case K::dump_ray: {
      const auto& insp = app_.inspection();
      if (!insp) throw std::runtime_error("no ray cast yet (use click first)");
      fail_if(write_new_file(c.arg, json_text(inspection_json(*insp, app_.replay_step()), 2) + "\n"));
      return Status::done;
    }
    case K::dump_stats: {
      nlohmann::json doc = app_.stats_json();
      doc["frames"] = frames_drawn_;
      sync_overlay();
      const std::optional<std::uint64_t> ramp_max = box_ramp_max();
      doc["boxes"] = {{"drawn", view_->boxes_drawn()},
                      {"matched", view_->boxes_matched()},
                      {"truncated", view_->boxes_truncated()},
                      {"instance_colors", view_->instance_colored()},
                      {"node_note", insight_.box_node_note(app_)},
                      {"visit_max", view_->boxes_visit_max()}};
      doc["tree"] = {{"swatch_max", insight_.tree_swatch_max(app_, ramp_max)},
                     {"swatch_of_boxes", ramp_max.has_value()}};
      doc["ab_window"] = insight_.ab_window_json();
      fail_if(write_new_file(c.arg, json_text(doc, 2) + "\n"));
      return Status::done;
    }
    case K::frames:
      if (!frames_target_) frames_target_ = frames_drawn_ + static_cast<std::uint64_t>(c.x);
      if (frames_drawn_ < *frames_target_) return Status::again;
      frames_target_.reset();
      return Status::done;
    case K::quit:
      quit_ = true;
      return Status::done;
    case K::flatten: {
      if (app_.loading_scene() || !app_.rest()) return Status::again;
      if (!flatten_wait_) {
        const std::string name = app_.rest()->accel->name();
        if (name != "tlas") throw std::runtime_error("the structure is " + name + "; the what-if needs tlas");
        std::vector<std::uint32_t> ids = parse_instance_ids(c.arg, app_.rest()->scene->scene.instances.size());
        flatten_scene_ = app_.rest()->scene;
        flatten_panel_.scene_identity = flatten_scene_.get();
        panels::set_flatten_selection(flatten_panel_, ids);
        flatten_wait_ = request_flatten(FlattenRequest::Kind::preview, std::move(ids));
      }
      const std::shared_ptr<const FlattenResult> r = flatten_.latest();
      if (!r || r->id < *flatten_wait_) return Status::again;
      flatten_wait_.reset();
      if (!r->error.empty()) throw std::runtime_error(r->error);
      note_flatten_prediction();
      return Status::done;
    }
    case K::flatten_commit: {
      // After `open`, the commit is of the new scene's prediction (there is
      // none yet): wait for the scene, as flatten and camera do, rather than
      // merge the old scene and throw the open away.
      if (!flatten_wait_ && app_.loading_scene()) return Status::again;
      if (!flatten_wait_) {
        const std::shared_ptr<const FlattenResult> r = flatten_.latest();
        if (!r || !r->figures || !app_.rest() || r->scene != app_.rest()->scene.get())
          throw std::runtime_error("no prediction of the shown scene (run flatten IDS first)");
        flatten_wait_ = request_flatten(FlattenRequest::Kind::commit, r->instances);
      }
      const std::shared_ptr<const FlattenResult> r = flatten_.latest();
      if (!r || r->id < *flatten_wait_) return Status::again;
      take_flatten_commit();
      if (!r->error.empty()) {
        flatten_wait_.reset();
        throw std::runtime_error(r->error);
      }
      // Done once the merged scene is shown and its build and heatmap are in.
      if (app_.loading_scene() || app_.scene_spec() != r->committed->spec || !app_.settled()) return Status::again;
      flatten_wait_.reset();
      return Status::done;
    }
    case K::dump_flatten: {
      note_flatten_prediction();
      const std::shared_ptr<const FlattenResult> r = flatten_.latest();
      nlohmann::json doc;
      if (r && !r->error.empty()) {  // the last job failed: say so
        doc = flatten_result_json(*r, flatten_spec_of(*r));
      } else {
        if (!flatten_prediction_) throw std::runtime_error("no flatten prediction yet (run flatten IDS first)");
        doc = flatten_result_json(*flatten_prediction_, flatten_prediction_spec_);
        // A commit of that prediction since: the merged scene it opened.
        if (r && r->kind == FlattenRequest::Kind::commit && r->committed &&
            r->instances == flatten_prediction_->instances && r->scene == flatten_prediction_->scene)
          doc["committed"] = r->committed->spec;
      }
      fail_if(write_new_file(c.arg, json_text(doc, 2) + "\n"));
      return Status::done;
    }
    case K::sweep: {
      // As the panel's Run, once the structure chosen so far is shown (the sweep starts from its options).
      if (!app_.settled()) return Status::again;
      panels::request_window("Cost of accuracy", true);
      accuracy_.params = c.arg;
      accuracy_.params_for = app_.config().structure.name;
      sweep_wait_ = request_sweep();
      if (!sweep_wait_) throw std::runtime_error(accuracy_.error);
      // What each setting starts from (the labels name only the swept values), as dump-stats names it.
      nlohmann::json options = nlohmann::json::object();
      for (std::string_view key : structure_option_keys(app_.config().structure.name))
        options[std::string(key)] = option_value(app_.config(), key);
      sweep_context_ = {{"scene", app_.scene_spec()},
                        {"camera", explicit_camera_spec(app_.camera())},  // render --camera takes it
                        {"size", {{"width", accuracy_.width}, {"height", accuracy_.height}}},
                        {"repeat", accuracy_.repeat},
                        {"options", options},
                        {"program", cli::program_json()}};
      return Status::done;
    }
    case K::dump_sweep: {
      if (!sweep_wait_) throw std::runtime_error("no sweep run yet (use sweep PARAMS first)");
      const std::shared_ptr<const SweepSnapshot> s = sweeps_.latest();
      if (!job_ended(s.get(), *sweep_wait_)) return Status::again;
      nlohmann::json doc = {{"structure", s->structure},
                            {"state", job_state_name(s->state)},
                            {"error", s->error},
                            {"triangles", s->triangles},
                            {"rays", s->rays},
                            {"ray_budget", accuracy_.ray_budget},
                            {"params", nlohmann::json::object()},
                            {"results", nlohmann::json::array()}};
      doc.update(sweep_context_);
      for (const SweepParam& p : s->params) doc["params"][p.name] = p.values;
      for (const SweepResult& r : s->results) doc["results"].push_back(cli::sweep_result_json(r, accuracy_.ray_budget));
      fail_if(write_new_file(c.arg, json_text(doc, 2) + "\n"));
      return Status::done;
    }
    case K::cancel:
      // The Cancel button of the Structure, Cost of accuracy or Robustness window.
      if (c.arg == "build")
        app_.cancel_build();
      else if (c.arg == "sweep")
        sweeps_.cancel();
      else
        robustness_.cancel();
      return Status::done;
    case K::robustness: {
      // As the panel's Run, once the structure chosen so far is shown (its own traversal is one row).
      if (!app_.settled()) return Status::again;
      panels::request_window("Robustness", true);
      if (c.x > 0) robustness_panel_.rays = c.x;
      lab_wait_ = request_robustness();
      if (!lab_wait_) throw std::runtime_error("no scene shown");
      return Status::done;
    }
    case K::dump_robustness: {
      if (!lab_wait_) throw std::runtime_error("no robustness run yet (use robustness [N] first)");
      const std::shared_ptr<const RobustnessSnapshot> s = robustness_.latest();
      if (!job_ended(s.get(), *lab_wait_)) return Status::again;
      nlohmann::json doc = {{"scene", s->scene},
                            {"structure", s->structure},
                            {"state", job_state_name(s->state)},
                            {"error", s->error},
                            {"program", cli::program_json()}};
      if (s->result) doc.update(cli::lab_result_json(*s->result));
      fail_if(write_new_file(c.arg, json_text(doc, 2) + "\n"));
      return Status::done;
    }
    case K::force_effect:
      fail_if(force_effect(app_.config(), c.arg, c.value == "on"));
      return Status::done;
    case K::play: {
      if (app_.loading_scene() || !app_.current()) return Status::again;
      const SceneEffects* fx = effects();
      if (!fx || !fx->per_frame_updates.on)
        throw std::runtime_error(app_.scene_spec() + ": per-frame updates are off (" +
                                 (fx ? fx->per_frame_updates.reason : std::string("no scene")) + ")");
      const std::shared_ptr<const DynamicsSnapshot> snap = dynamics_.latest();
      const bool ours = snap && snap->scene == app_.rest()->scene.get();
      if (!snap || !ours) {  // the worker has not set the scene up yet
        player_.playing = true;
        return Status::again;
      }
      if (!snap->error.empty()) throw std::runtime_error(snap->error);
      if (!play_target_) {
        play_target_ = snap->frames + static_cast<std::uint64_t>(c.x);
        player_.playing = true;
      }
      if (snap->frames < *play_target_) return Status::again;
      if (snap->frame) app_.show_frame(snap->frame, snap->scene);  // what the next command sees
      play_target_.reset();
      player_.playing = false;
      return Status::done;
    }
    case K::dump_dynamics: {
      const SceneEffects* fx = effects();
      if (!fx) throw std::runtime_error("no scene shown yet");
      nlohmann::json doc = {
          {"scene", app_.scene_spec()}, {"effects", effects_json(*fx)}, {"program", cli::program_json()}};
      const std::shared_ptr<const DynamicsSnapshot> snap = dynamics_.latest();
      if (snap && app_.rest() && snap->scene == app_.rest()->scene.get()) {
        nlohmann::json frames = nlohmann::json::array();
        for (const FrameStats& f : snap->history) frames.push_back(cli::frame_stats_json(f));
        doc["dynamics"] = {{"frames_stepped", snap->frames}, {"setup_ms", snap->setup_ms}, {"duration", snap->duration},
                           {"animates", snap->animates},     {"error", snap->error},       {"history", frames}};
        doc["dynamics"]["shown_frame"] = nullptr;
        if (app_.showing_frame() && snap->frame == app_.current()) {
          const auto root = app_.current()->nodes.box(0);
          doc["dynamics"]["shown_frame"] = {
              {"time", snap->frame_time},
              {"build_ms", snap->frame_build_ms},
              {"animator_tree", snap->frame_is_animator_tree},
              {"node_count", app_.current()->accel->build_stats().node_count},
              {"sah_cost", app_.current()->accel->build_stats().sah_cost},
              {"root_lo", root ? std::vector<float>{root->lo.x, root->lo.y, root->lo.z} : std::vector<float>{}},
              {"root_hi", root ? std::vector<float>{root->hi.x, root->hi.y, root->hi.z} : std::vector<float>{}}};
        }
      } else {
        doc["dynamics"] = nullptr;
      }
      fail_if(write_new_file(c.arg, json_text(doc, 2) + "\n"));
      return Status::done;
    }
    case K::window: {
      // Two panels show only while the scene or structure calls for them: an
      // open request for one that is not drawn would wait, unseen, until it
      // is (a later scene's panel popping open), so it fails instead; a close
      // request has nothing to do then.
      const bool open = c.value == "open";
      if (c.arg == "Flatten what-if" || c.arg == "Dynamics") {
        if (!app_.settled()) return Status::again;
        std::string why;
        if (c.arg == "Flatten what-if") {
          const std::string name = app_.rest() ? app_.rest()->accel->name() : std::string("none");
          if (name != "tlas") why = "the structure is " + name + "; the panel shows while a tlas is shown";
        } else if (const SceneEffects* fx = effects(); !fx || !fx->per_frame_updates.on) {
          why = app_.scene_spec() + ": per-frame updates are off (" +
                (fx ? fx->per_frame_updates.reason : std::string("no scene")) + "); the panel shows while they are on";
        }
        if (!why.empty()) {
          if (open) throw std::runtime_error(c.arg + " is not shown now: " + why);
          return Status::done;
        }
      }
      panels::request_window(c.arg, open);
      return Status::done;
    }
    case K::scenario:
    case K::dump_scenario:
    case K::dump_insight:
    case K::select_region:
    case K::pin_a:
    case K::dump_ab:
      return insight_.execute(app_, c);
  }
  return Status::done;
}

int Gui::run() {
  catch_quit_signals();  // once the window is open: the headless demo (no window) keeps Ctrl-C's default
  // What to show first: the file given, else (with settings) the last
  // scene, else the demo. A script that starts with `open` loads nothing
  // before it.
  initial_scene_ = options_.scene                                                   ? *options_.scene
                   : (options_.use_settings && !app_.settings().last_scene.empty()) ? app_.settings().last_scene
                                                                                    : std::string(kDemoScene);
  if (!skip_initial_open_) {
    path_field_ = initial_scene_;
    app_.open_scene(initial_scene_);
  }

  GLFWwindow* win = window_->window();
  while (!quit_ && !glfwWindowShouldClose(win) && g_quit_signal == 0) {
    // Idle (nothing building, tracing or scripted): sleep until input
    // arrives; otherwise keep frames coming so results show up promptly.
    // One more frame after the workers go quiet picks up their last result.
    const bool busy = script_ || app_.build_status().busy || app_.heatmap_busy() || sweeps_.busy() || insight_.busy() ||
                      robustness_.busy() || dynamics_.busy() || player_.playing;
    if (busy || was_busy_)
      glfwPollEvents();
    else
      glfwWaitEventsTimeout(0.25);
    was_busy_ = busy;

    const int fbw = window_->width(), fbh = window_->height();
    int ww = 0, wh = 0;
    glfwGetWindowSize(win, &ww, &wh);
    if (fbw <= 0 || fbh <= 0) continue;  // minimised

    for (const std::string& path : dropped_) {
      path_field_ = path;
      app_.open_scene(path);
    }
    dropped_.clear();

    imgui_->new_frame();
    const ImGuiIO& io = ImGui::GetIO();
    const panels::PanelLayout layout{imgui_->scale(), io.DisplaySize.x, io.DisplaySize.y};
    handle_input(fbw, fbh, ww, wh);

    const AppState::FrameUpdate u = app_.update(fbw, fbh);
    if (u.scene_changed) save_settings_now();
    // A last scene that no longer opens falls back to the demo once.
    if (!app_.current() && !app_.error().empty() && !fallback_tried_ && !script_ && initial_scene_ != kDemoScene &&
        !app_.build_status().busy) {
      fallback_tried_ = true;
      app_.open_scene(kDemoScene);
    }

    if (script_) {
      const double now = std::chrono::duration<double>(Clock::now() - start_).count();
      try {
        const ScriptRunner::State s = script_->advance(*this, now);
        if (s == ScriptRunner::State::failed) {
          std::fprintf(stderr, "accelviz: %s\n", script_->error().c_str());
          exit_code_ = 1;
          quit_ = true;
        } else if (s == ScriptRunner::State::finished) {
          quit_ = true;
        }
      } catch (const std::exception& e) {
        std::fprintf(stderr, "accelviz: script: %s\n", e.what());
        exit_code_ = 1;
        quit_ = true;
      }
    }

    draw_panels(layout);
    report_errors();

    const std::string title = app_.scene_spec().empty() ? "accelviz" : "accelviz - " + app_.scene_spec();
    if (title != last_title_) {
      glfwSetWindowTitle(win, title.c_str());
      last_title_ = title;
    }

    try {
      const bool uploaded = view_->sync(app_);
      const std::string key = redraw_key(fbw, fbh);
      if (uploaded || key != last_redraw_key_) {
        view_->draw(app_, fbw, fbh);
        last_redraw_key_ = key;
      }
    } catch (const std::exception& e) {
      // A GL or shader failure is reported, not fatal: the panels stay usable.
      app_.set_error(e.what());
      report_errors();
      last_redraw_key_.clear();
    }
    view_->renderer().present(fbw, fbh);
    imgui_->render();
    window_->swap_buffers();
    ++frames_drawn_;
    if (options_.use_settings)
      if (const std::string e = imgui_->save_layout(); !e.empty()) app_.set_error(e);
  }
  save_settings_now();
  if (options_.use_settings)
    if (const std::string e = imgui_->save_layout(true); !e.empty()) std::fprintf(stderr, "accelviz: %s\n", e.c_str());
  report_errors();
  // Ended by a signal: the status a shell expects of one (128 + its number), after the saves.
  return g_quit_signal != 0 ? 128 + static_cast<int>(g_quit_signal) : exit_code_;
}

}  // namespace

bool display_available() {
  const char* x = std::getenv("DISPLAY");
  const char* w = std::getenv("WAYLAND_DISPLAY");
  return (x && *x) || (w && *w);
}

bool settings_disabled_by_environment() {
  const char* v = std::getenv("ACCELVIZ_NO_SETTINGS");
  return v && *v && std::string_view(v) != "0";
}

int run_gui(const GuiOptions& options) {
  use_fixed_malloc_thresholds();  // rebuilds reuse mapped pages; the Accuracy panel's sweeps compare fairly
  GuiOptions o = options;
  if (o.script || settings_disabled_by_environment()) o.use_settings = false;

  // Parse the script before opening a window: a bad line fails at once.
  std::optional<ScriptRunner> runner;
  std::vector<ScriptCommand> commands;
  if (o.script) {
    try {
      commands = load_script(*o.script);
    } catch (const ScriptError& e) {
      std::fprintf(stderr, "accelviz: %s\n", e.what());
      return 1;
    }
  }
  const bool script_opens_first = !commands.empty() && commands.front().kind == ScriptCommand::Kind::open;
  if (o.script) runner.emplace(std::move(commands), *o.script);

  AppSettings settings;
  std::string settings_error;
  if (o.use_settings) {
    LoadedSettings loaded = load_settings(settings_file(config_dir()));
    settings = std::move(loaded.settings);
    settings_error = std::move(loaded.error);
    o.save_settings = !loaded.leave_file;
  }
  Gui gui(o, std::move(settings), std::move(runner), settings_error);
  if (script_opens_first && !o.scene) gui.skip_initial_open();
  return gui.run();
}

}  // namespace accelviz
