#include "ui/app/app_state.h"

#include <algorithm>
#include <cmath>

#include "core/accel/tlas/tlas.h"
#include "core/query/camera.h"
#include "core/scene/effects.h"
#include "core/util/one_line.h"
#include "core/util/timing.h"

namespace accelviz {
namespace {

float aspect_of(int w, int h) {
  return w > 0 && h > 0 ? static_cast<float>(w) / static_cast<float>(h) : 1.0f;
}

}  // namespace

AppState::AppState(AppSettings settings, BuildWorker::LoadFn load, BuildWorker::BuildFn build)
    : settings_(std::move(settings)), builds_(std::move(load), std::move(build)) {}

void AppState::open_scene(const std::string& spec) {
  wanted_scene_ = spec;
  reload_ = true;
  scene_loading_ = true;
  follow_effects_ = true;
  set_message("loading " + spec);
}

void AppState::open_loaded_scene(std::shared_ptr<const LoadedScene> scene) {
  if (!scene) return;
  wanted_scene_ = scene->spec;
  preloaded_ = std::move(scene);
  reload_ = true;
  scene_loading_ = true;
  set_message("opening " + wanted_scene_);
}

std::string AppState::set_option(std::string_view key, std::string_view value) {
  const std::string e = apply_option(settings_.config, key, value);
  if (!e.empty()) set_error(e);
  return e;
}

void AppState::cancel_build() {
  builds_.cancel();
  // What is shown becomes what is wanted, so the cancelled choice is not
  // requested again next frame.
  if (current_) {
    requested_ = current_->choice;
    requested_scene_ = wanted_scene_ = current_->scene->spec;
    settings_.config.structure.name = current_->choice.name;
    settings_.config.structure.options = current_->choice.options;
  } else {
    requested_.reset();
    wanted_scene_.clear();
  }
  reload_ = false;
  scene_loading_ = false;
  set_message("build cancelled");
}

void AppState::set_error(std::string e) {
  error_ = std::move(e);
  if (!error_.empty()) new_errors_.push_back(error_);
}

void AppState::set_message(std::string m) {
  message_ = std::move(m);
  error_.clear();
}

std::vector<std::string> AppState::take_new_errors() {
  std::vector<std::string> out;
  out.swap(new_errors_);
  return out;
}

AppState::HeatmapKey AppState::heatmap_key(int w, int h) const {
  HeatmapKey k;
  k.structure = current_.get();
  const Camera cam = camera();
  k.position = cam.position;
  k.forward = cam.forward;
  k.up = cam.up;
  k.yfov = cam.yfov;
  k.options = view_heatmap_options(config(), w, h);
  k.shadows = current_ && shadow_rays_wanted(current_->scene->scene, config().effects);
  k.gpu = config().view.heatmap_gpu;
  return k;
}

AppState::FrameUpdate AppState::update(int view_width, int view_height) {
  FrameUpdate u;
  // The previous frame's time (with its GPU heatmap step's) sizes this frame's GPU budget.
  const auto now = std::chrono::steady_clock::now();
  const double last_frame_ms =
      last_update_ ? std::chrono::duration<double, std::milli>(now - *last_update_).count() : 0.0;
  last_update_ = now;
  double step_ms = 0.0;
  view_w_ = view_width;
  view_h_ = view_height;

  // 1. A build when what is wanted differs from what was asked for last.
  const StructureChoice& wanted = config().structure;
  if (!wanted_scene_.empty() &&
      (reload_ || wanted_scene_ != requested_scene_ || !requested_ || !same_build(*requested_, wanted))) {
    // A structure the user chose (not the app for an instanced scene) is kept from then on.
    if (requested_ && requested_->name != wanted.name) left_for_tlas_.clear();
    BuildRequest r{wanted_scene_, wanted, reload_, {}};
    if (preloaded_ && preloaded_->spec == wanted_scene_) r.preloaded = preloaded_;
    r.follow_effects = follow_effects_;
    r.forces = config().effects;
    if (wanted.name == "tlas") r.single_level = left_for_tlas_;
    follow_effects_ = false;
    preloaded_.reset();
    request_id_ = builds_.request(std::move(r));
    if (scene_loading_) scene_request_id_ = request_id_;
    requested_scene_ = wanted_scene_;
    requested_ = wanted;
    reload_ = false;
  }

  // 2. Finished builds: only the latest request counts.
  for (BuildOutcome& o : builds_.take_outcomes()) {
    // A later request made while the scene loads carries the scene too.
    if (o.id >= scene_request_id_ && o.result != BuildOutcome::Result::cancelled) scene_loading_ = false;
    if (o.id != request_id_) continue;
    if (o.result == BuildOutcome::Result::built) {
      const bool new_scene = !rest_ || rest_->scene != o.built->scene;
      // The scene's effects chose the level (BuildRequest::follow_effects): the choice follows.
      std::string switched;
      if (!o.switched_from.empty()) {
        settings_.config.structure.name = o.built->choice.name;
        if (requested_) requested_->name = o.built->choice.name;
        left_for_tlas_ = o.built->choice.name == "tlas" ? o.switched_from : std::string();
        switched = o.built->choice.name == "tlas"
                       ? "; " + o.switch_reason + ": two-level structure (tlas) instead of " + o.switched_from
                       : "; no mesh instanced twice: back to " + o.built->choice.name + " from tlas";
      }
      current_ = std::move(o.built);
      rest_ = current_;
      u.structure_changed = true;
      const Scene& scene = current_->scene->scene;
      // tlas over a scene that instances nothing twice: allowed (to see what a level costs), said.
      if (current_->choice.name == "tlas" && !decide_effects(scene, config().effects).two_level.on)
        switched += "; no mesh is instanced twice (two-level off): tlas holds its " +
                    count_of(std::max<std::size_t>(1, scene.instances.size()), "instance");
      if (new_scene) {
        u.scene_changed = true;
        camera_ = ViewCamera::scene_default(scene, aspect_of(view_w_, view_h_));
        clear_inspection();
        if (!current_->scene->in_memory) {
          settings_.last_scene = current_->scene->spec;
          add_recent(settings_, current_->scene->spec);
        }
        std::string m =
            "opened " + current_->scene->spec + " (" + std::to_string(scene.triangles.size()) + " triangles)";
        if (!scene.report.warnings.empty())
          m += ", " + std::to_string(scene.report.warnings.size()) +
               " loader warning(s): " + scene.report.warnings.front();
        if (!camera_.framing_problem.empty()) m += "; " + camera_.framing_problem;
        set_message(m + switched);
      } else {
        set_message("built " + describe_structure(current_->choice) + " in " +
                    std::to_string(static_cast<long long>(std::lround(current_->wall_ms))) + " ms" + switched);
        recast();
      }
    } else if (o.result == BuildOutcome::Result::failed) {
      set_error(o.error);
      if (o.scene_error) {
        // Keep the scene that is shown; later structure changes build over it.
        wanted_scene_ = requested_scene_ = scene_spec();
        if (current_)
          requested_ = current_->choice;
        else
          requested_.reset();
      }
    }
  }

  // 3. The heatmap of this view, restarted whenever anything it shows changed.
  if (current_ && view_w_ > 0 && view_h_ > 0) {
    const HeatmapKey key = heatmap_key(view_w_, view_h_);
    if (!heatmap_requested_ || !(*heatmap_requested_ == key)) {
      HeatmapRequest r{current_, camera(), key.options};
      r.shadow_lights = shadow_lights(current_->scene->scene, key.shadows);
      heatmap_on_gpu_ = false;
      gpu_frame_shown_ = false;
      gpu_fallback_.reset();
      gpu_note_.clear();
      if (gpu_job_) gpu_job_->cancel();
      if (key.gpu) {
        if (!gpu_job_)
          gpu_note_ = "no GPU tracer in this session";
        else if (current_->choice.name != "bvh")
          gpu_note_ = "only the bvh structure is traced on the GPU";
        else {
          try {
            // Primary rays only: shadow rays (scene lights) are not traced on the GPU.
            HeatmapRequest primary = r;
            primary.shadow_lights.clear();
            heatmaps_.cancel();
            gpu_job_->start(primary, ++gpu_frame_id_);
            heatmap_on_gpu_ = true;
            gpu_fallback_ = r;
          } catch (const std::exception& e) {
            gpu_note_ = e.what();
          }
        }
      }
      if (!heatmap_on_gpu_) heatmaps_.request(std::move(r));
      heatmap_requested_ = key;
    }
    // The GPU trace's bands for this frame (the window stays responsive;
    // the old heatmap stays up until the new one is complete).
    if (heatmap_on_gpu_ && gpu_job_ && gpu_job_->busy()) {
      try {
        const double budget =
            gpu_heatmap_budget_ms(static_cast<double>(config().view.heatmap_gpu_ms), last_frame_ms, last_gpu_step_ms_);
        const auto t_step = std::chrono::steady_clock::now();
        auto f = gpu_job_->step(budget);
        step_ms = ms_since(t_step);
        if (f) {
          heatmap_ = std::move(f);
          gpu_frame_shown_ = true;
          shown_on_gpu_ = true;
          u.heatmap_changed = true;
        }
      } catch (const std::exception& e) {
        gpu_note_ = e.what();
        heatmap_on_gpu_ = false;
        if (gpu_fallback_) heatmaps_.request(std::move(*gpu_fallback_));
        gpu_fallback_.reset();
      }
    }
    // Query options changed: the inspected ray is re-cast with them.
    const QueryOptions& q = config().structure.query;
    if (inspection_ && q != inspected_query_) recast();
  }
  if (auto latest = heatmaps_.latest(); !heatmap_on_gpu_ && latest && latest != heatmap_) {
    heatmap_ = std::move(latest);
    shown_on_gpu_ = false;
    u.heatmap_changed = true;
  }
  if (const auto [failed, why] = heatmaps_.failure();
      failed != 0 && failed != heatmap_failure_shown_ && failed == heatmaps_.latest_request()) {
    heatmap_failure_shown_ = failed;
    // Said once while it stays the same (each camera move is a new job that fails the same way).
    if (std::string e = "heatmap not traced: " + why; e != error_) set_error(std::move(e));
  }
  last_gpu_step_ms_ = step_ms;
  return u;
}

bool AppState::show_frame(std::shared_ptr<const BuiltStructure> frame, const LoadedScene* rest_scene) {
  if (!frame || !rest_ || rest_->scene.get() != rest_scene || frame->choice.name != rest_->choice.name ||
      !same_build(frame->choice, rest_->choice))
    return false;
  if (current_ != frame) {
    current_ = std::move(frame);
    recast();
  }
  return true;
}

void AppState::show_rest() {
  if (current_ == rest_) return;
  current_ = rest_;
  recast();
}

bool AppState::settled() const {
  if (!builds_.idle()) return false;
  const StructureChoice& wanted = config().structure;
  if (!wanted_scene_.empty() &&
      (reload_ || wanted_scene_ != requested_scene_ || !requested_ || !same_build(*requested_, wanted)))
    return false;
  if (!current_ || view_w_ <= 0 || view_h_ <= 0) return true;
  if (!heatmap_requested_ || !(*heatmap_requested_ == heatmap_key(view_w_, view_h_))) return false;
  if (heatmap_on_gpu_) return gpu_frame_shown_;
  // Failed, and said: update() has taken the failure into the status line. (Reading the worker's
  // failure here settled a frame early: a failure after that frame's update() left `wait` to
  // return before the status said it.)
  if (heatmap_failure_shown_ != 0 && heatmap_failure_shown_ == heatmaps_.latest_request() && !heatmaps_.busy())
    return true;
  return heatmap_ && heatmap_->id == heatmaps_.latest_request() && heatmap_->complete;
}

std::optional<GpuHeatmapJob::Progress> AppState::gpu_heatmap_progress() const {
  if (!heatmap_on_gpu_ || !gpu_job_ || !gpu_job_->busy()) return std::nullopt;
  return gpu_job_->progress();
}

void AppState::reset_camera() {
  if (const Scene* s = scene()) camera_ = ViewCamera::scene_default(*s, aspect_of(view_w_, view_h_));
}

void AppState::frame_selection() {
  const Scene* s = scene();
  if (!s) return;
  Aabb box = s->bounds();
  const ViewSettings& v = config().view;
  const auto* tlas = dynamic_cast<const Tlas*>(current_->accel.get());
  if (v.show_boxes && tlas && current_->nodes.kind() == "tlas" && v.box_level == BoxLevel::blas) {
    // The bottom level: the selected BLAS subtree in every shown instance
    // (or in the one instance chosen), else the chosen instance's world box.
    if (v.box_mode == BoxMode::subtree) {
      NodeSelection sel;
      sel.mode = BoxMode::subtree;
      sel.node = static_cast<std::uint32_t>(v.box_node);
      Aabb u;
      for (const NodeBox& b : select_blas_boxes(*tlas, sel, std::size_t{1} << 20, v.box_instance).boxes)
        u.extend(b.bounds);
      if (!u.is_empty()) box = u;
    } else if (v.box_instance >= 0 && static_cast<std::size_t>(v.box_instance) < tlas->instances().size()) {
      box = tlas->instances()[static_cast<std::size_t>(v.box_instance)].world_bounds;
    }
  } else if (v.show_boxes && v.box_mode == BoxMode::subtree) {
    if (const auto b = current_->nodes.box(static_cast<std::uint32_t>(v.box_node))) box = *b;
  }
  camera_.unfix();
  camera_.orbit.frame(box, aspect_of(view_w_, view_h_));
}

void AppState::use_scene_camera(int index) {
  const Scene* s = scene();
  if (!s || index < 0 || index >= static_cast<int>(s->cameras.size())) return;
  camera_ = ViewCamera::scene_camera_view(*s, index);
}

void AppState::set_camera_spec(const std::string& spec) {
  const Scene* s = scene();
  if (!s) throw std::invalid_argument("no scene loaded yet (use wait after open)");
  camera_ = ViewCamera::from_spec(spec, *s, aspect_of(view_w_, view_h_));
}

std::optional<glm::vec3> AppState::pick(int x, int y) const {
  if (!current_ || x < 0 || y < 0 || x >= view_w_ || y >= view_h_) return std::nullopt;
  const Ray ray = primary_ray(camera(), x, y, view_w_, view_h_);
  if (!current_->accel->ray_problem(ray).empty()) return std::nullopt;  // Embree's reach: its query would throw
  const Hit hit = current_->accel->closest_hit(ray, config().structure.query);
  if (!hit.valid()) return std::nullopt;
  return ray.at(hit.t);
}

std::string AppState::cast_ray(int x, int y) {
  if (!current_) return "no structure yet (use wait after open)";
  if (x < 0 || y < 0 || x >= view_w_ || y >= view_h_)
    return "pixel " + std::to_string(x) + "," + std::to_string(y) + " is outside the " + std::to_string(view_w_) + "x" +
           std::to_string(view_h_) + " view";
  try {
    inspection_ = inspect_pixel(*current_, camera(), x, y, view_w_, view_h_, config().structure.query);
  } catch (const std::exception& e) {  // a structure that refuses the ray (Embree's reach)
    clear_inspection();
    return "pixel " + std::to_string(x) + "," + std::to_string(y) + " not inspected: " + e.what();
  }
  inspected_query_ = config().structure.query;
  ++inspection_version_;
  inspection_recast_ = false;
  replay_step_ = inspection_->trace.steps.empty() ? 0 : inspection_->trace.steps.size() - 1;
  return {};
}

void AppState::recast() {
  if (!inspection_ || !current_) return;
  try {
    inspection_ = inspect_ray(*current_, *inspection_, config().structure.query);
  } catch (const std::exception& e) {  // the new structure refuses the inspected ray (Embree's reach)
    clear_inspection();
    set_error(std::string("inspected ray dropped: ") + e.what());
    return;
  }
  inspected_query_ = config().structure.query;
  ++inspection_version_;
  inspection_recast_ = true;
  replay_step_ = inspection_->trace.steps.empty() ? 0 : inspection_->trace.steps.size() - 1;
}

void AppState::set_replay_step(std::size_t step) {
  if (!inspection_) return;
  const std::size_t n = inspection_->trace.steps.size();
  replay_step_ = n == 0 ? 0 : std::min(step, n - 1);
}

void AppState::clear_inspection() {
  if (inspection_) ++inspection_version_;
  inspection_.reset();
  replay_step_ = 0;
}

nlohmann::json AppState::stats_json() const {
  nlohmann::json j;
  j["scene"] = scene_spec();
  j["triangles"] = current_ ? current_->scene->scene.triangles.size() : 0;
  j["error"] = error_;
  j["message"] = message_;
  const BuildWorker::Status st = builds_.status();
  j["building"] = st.busy;
  j["camera"] = camera_.spec();
  j["view"] = nullptr;
  j["build"] = nullptr;
  j["structure"] = current_ ? current_->choice.name : std::string();
  if (current_) {
    AppConfig c;
    c.structure = current_->choice;
    nlohmann::json options = nlohmann::json::object();
    for (std::string_view key : structure_option_keys(c.structure.name))
      options[std::string(key)] = option_value(c, key);
    j["options"] = options;
    const BuildStats& b = current_->accel->build_stats();
    j["build"] = {{"build_ms", b.build_ms},
                  {"wall_ms", current_->wall_ms},
                  {"nodes", b.node_count},
                  {"leaves", b.leaf_count},
                  {"max_depth", b.max_depth},
                  {"avg_leaf_depth", b.avg_leaf_depth},
                  {"memory_bytes", b.memory_bytes},
                  {"sah_cost", b.sah_cost},
                  {"extra", b.extra},
                  {"inspectable", current_->accel->inspectable()}};
  }
  if (heatmap_) {
    const HeatmapSummary& s = heatmap_->summary;
    j["view"] = {{"width", heatmap_->image.width},
                 {"height", heatmap_->image.height},
                 {"structure", heatmap_->request.structure ? heatmap_->request.structure->accel->name() : ""},
                 {"metric", metric_name(heatmap_->image.metric)},
                 {"complete", heatmap_->complete},
                 {"stride", heatmap_->stride},
                 {"rays", s.rays},
                 {"hits", s.hits},
                 {"mean_nodes", s.mean_nodes},
                 {"max_nodes", s.max_nodes},
                 {"mean_prims", s.mean_prims},
                 {"max_prims", s.max_prims},
                 {"mean_instances", s.mean_instances},
                 {"max_instances", s.max_instances},
                 {"mean_value", s.mean_value},
                 {"max_value", s.max_value},
                 {"shadow_rays", s.shadow_rays},
                 {"shadowed", s.shadowed},
                 {"mean_shadow_nodes", s.mean_shadow_nodes},
                 {"mean_shadow_prims", s.mean_shadow_prims},
                 {"render_ms", s.render_ms},
                 {"rays_per_s", s.rays_per_s},
                 {"device", shown_on_gpu_ ? "gpu" : "cpu"},
                 {"gpu_note", gpu_note_}};
  }
  // The GPU trace of the current view while it runs (null otherwise).
  j["gpu_trace"] = nullptr;
  if (const auto p = gpu_heatmap_progress())
    j["gpu_trace"] = {{"rows_done", p->rows_done}, {"rows", p->rows}, {"bands", p->bands}, {"trace_ms", p->trace_ms}};
  return j;
}

ScreenshotInfo AppState::screenshot_info(float scale_min, float scale_max) const {
  ScreenshotInfo info;
  info.scene = scene_spec();
  info.triangles = current_ ? current_->scene->scene.triangles.size() : 0;
  info.camera_spec = camera_.spec();
  info.camera = camera();
  info.width = view_w_;
  info.height = view_h_;
  info.config = config();
  // The structure shown, which may lag behind the one being built.
  if (current_) {
    info.config.structure.name = current_->choice.name;
    info.config.structure.options = current_->choice.options;
  }
  info.scale_min = scale_min;
  info.scale_max = scale_max;
  if (inspection_) {
    info.ray_pixel = std::make_pair(inspection_->x, inspection_->y);
    info.ray_camera = inspection_->camera;
    info.ray_steps = inspection_->trace.steps.size();
    if (replay_step_ + 1 < info.ray_steps) info.ray_step = replay_step_;
  }
  return info;
}

}  // namespace accelviz
