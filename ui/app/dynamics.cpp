#include "ui/app/dynamics.h"

#include <chrono>
#include <cmath>
#include <exception>
#include <optional>

#include "core/accel/factory.h"
#include "core/accel/tlas/tlas.h"
#include "core/util/timing.h"

namespace accelviz {

std::string force_effect(AppConfig& config, const std::string& name, bool on) {
  EffectForces f = config.effects;
  if (name == "textures") return "force-effect textures: cannot be forced (no view draws textures or materials)";
  if (!set_force(f, name))
    return "force-effect: unknown effect '" + name + "' (valid: shadow-rays, per-frame-updates, two-level)";
  if (!on) {
    if (name == "shadow-rays") f.shadow_rays = false;
    if (name == "per-frame-updates") f.per_frame_updates = false;
    if (name == "two-level") f.two_level = false;
  }
  config.effects = f;
  if (name == "two-level" && on) config.structure.name = "tlas";
  return {};
}

nlohmann::json effects_json(const SceneEffects& effects) {
  nlohmann::json out = nlohmann::json::array();
  for (const Effect& e : effects.list())
    out.push_back(
        {{"name", e.name}, {"on", e.on}, {"forced", e.forced}, {"forceable", e.forceable}, {"reason", e.reason}});
  return out;
}

// ---- worker -------------------------------------------------------------------

struct DynamicsWorker::State {
  std::shared_ptr<const LoadedScene> scene;
  /// The `tlas` choice the animator's structure was built with (none: the
  /// defaults, when the view shows another structure).
  std::optional<StructureChoice> tlas_choice;
  std::unique_ptr<Tlas> tlas;
  std::unique_ptr<SceneAnimator> animator;
  std::shared_ptr<DynamicsSnapshot> snap;  ///< copied before each publish
};

namespace {
using Published = std::shared_ptr<const DynamicsSnapshot>;
/// The view shows the two-level structure: the animator's own tree is the frame.
bool shows_tlas(const DynamicsRequest& r) {
  return r.structure && r.structure->name == "tlas";
}
/// The animator's structure options: the view's `tlas` choice, as the
/// factory (core/accel/factory.cpp) builds it, or the defaults.
TlasOptions animator_tlas_options(const std::optional<StructureChoice>& choice) {
  TlasOptions to;
  if (choice) {
    to.blas = choice->options.bvh;
    if (to.blas.threads == 0) to.blas.threads = choice->options.threads;
  }
  to.blas.compute_epo = false;
  to.tlas = to.blas;
  return to;
}
}  // namespace

DynamicsWorker::DynamicsWorker()
    : state_(std::make_shared<State>()),
      worker_(
          [st = state_](const DynamicsRequest& r, std::uint64_t, const auto& keep_going, const auto& publish) {
            State& s = *st;
            if (!r.scene) {  // nothing to play: let the last scene and its structure go
              s = State{};
              publish(nullptr);
              return;
            }
            // A new scene, or the view's two-level structure with other
            // options than the animator's: set the animator up afresh.
            const bool new_options = shows_tlas(r) && (!s.tlas_choice || !same_build(*s.tlas_choice, *r.structure));
            if (s.scene != r.scene || new_options) {
              // The animator's own two-level structure: the view's when it
              // shows `tlas` (its frames are then this very tree), else one
              // with default options (the app's structure is whatever the
              // user chose; the animator needs a Tlas).
              s.animator.reset();
              s.tlas.reset();
              s.tlas_choice = shows_tlas(r) ? r.structure : std::nullopt;
              s.scene = r.scene;
              s.snap = std::make_shared<DynamicsSnapshot>();
              s.snap->scene = r.scene.get();
              s.snap->spec = r.scene->spec;
              s.snap->animates = scene_animates(r.scene->scene);
              s.snap->duration = animation_duration(r.scene->scene);
              {  // also when nothing animates but the user forced per-frame updates on
                const auto t0 = std::chrono::steady_clock::now();
                try {
                  s.tlas = std::make_unique<Tlas>(r.scene->scene, animator_tlas_options(s.tlas_choice),
                                                  [&](double) { return keep_going(); });
                  AnimatorOptions ao;
                  ao.rebuild_ratio = r.rebuild_ratio;
                  s.animator = std::make_unique<SceneAnimator>(r.scene->scene, *s.tlas, ao);
                } catch (const BuildCancelled&) {
                  s.scene.reset();  // set up again with the next request
                  return;
                } catch (const std::exception& e) {
                  s.snap->error = std::string("dynamics: ") + e.what();
                }
                s.snap->setup_ms = ms_since(t0);
              }
              publish(Published(std::make_shared<DynamicsSnapshot>(*s.snap)));
            }
            if (!s.animator || !keep_going()) return;
            try {
              const FrameStats f = s.animator->step(r.time);
              s.snap->history.push_back(f);
              if (s.snap->history.size() > kDynamicsHistory) s.snap->history.erase(s.snap->history.begin());
              ++s.snap->frames;
            } catch (const std::exception& e) {
              s.snap->error = std::string("dynamics: ") + e.what();
            }
            if (r.structure && s.snap->error.empty() && !s.snap->history.empty()) {
              // The frame for display: the scene posed at this time (what is
              // drawn, and what primitive ids name) and the structure over
              // it. For `tlas` that is the animator's own tree as this step
              // left it (refitted or rebuilt per its policy), frozen by a
              // snapshot, so the view shows what the plots measure; any
              // other structure is built over the pose as the build worker
              // would build it.
              const auto t0 = std::chrono::steady_clock::now();
              try {
                auto posed = std::make_shared<LoadedScene>();
                posed->spec = r.scene->spec;
                posed->scene = posed_scene(r.scene->scene, s.snap->history.back().time);
                std::shared_ptr<const Accelerator> accel;
                const bool own = shows_tlas(r) && s.tlas;
                if (own) {
                  accel = s.tlas->snapshot();
                } else {
                  StructureChoice choice = *r.structure;
                  choice.options.scene = &posed->scene;
                  accel = build_accelerator(choice.name, posed->scene.triangles, choice.options,
                                            [&](double) { return keep_going(); });
                }
                s.snap->frame_is_animator_tree = own;
                auto built = std::make_shared<BuiltStructure>();
                built->nodes = StructureNodes::of(*accel);
                built->accel = std::move(accel);
                built->scene = std::move(posed);
                built->choice = *r.structure;
                built->wall_ms = ms_since(t0);
                s.snap->frame = std::move(built);
                s.snap->frame_time = s.snap->history.back().time;
                s.snap->frame_build_ms = ms_since(t0);
              } catch (const BuildCancelled&) {
                // superseded: the next request poses its own frame
              } catch (const std::exception& e) {
                s.snap->error = std::string("dynamics: frame structure: ") + e.what();
              }
            }
            // Published even when superseded: the frame was stepped and belongs
            // to the history (the store rule below keeps the newest scene's).
            publish(Published(std::make_shared<DynamicsSnapshot>(*s.snap)));
          },
          {.store = [](std::uint64_t, Published&& p, bool, bool, Published& latest) { latest = std::move(p); }}) {}

// ---- player -------------------------------------------------------------------

void DynamicsPlayer::seek(float t) {
  if (duration > 0.0f) {
    t = std::fmod(t, duration);
    if (t < 0.0f) t += duration;
  }
  time_ = std::max(0.0f, t);
  dirty_ = true;
}

bool DynamicsPlayer::tick(double dt, bool worker_busy) {
  if (playing && dt > 0.0) seek(time_ + static_cast<float>(dt) * speed);
  if (worker_busy || !dirty_) return false;
  if (time_ == requested_ && !playing) {
    dirty_ = false;
    return false;
  }
  requested_ = time_;
  dirty_ = false;
  return true;
}

}  // namespace accelviz
