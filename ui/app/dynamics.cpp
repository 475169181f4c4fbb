#include "ui/app/dynamics.h"

#include <chrono>
#include <cmath>
#include <exception>
#include <optional>

#include "core/accel/factory.h"
#include "core/accel/tlas/tlas.h"

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
  std::unique_ptr<Tlas> tlas;
  std::unique_ptr<SceneAnimator> animator;
  std::shared_ptr<DynamicsSnapshot> snap;  ///< copied before each publish
};

namespace {
using Published = std::shared_ptr<const DynamicsSnapshot>;
double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
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
            if (s.scene != r.scene) {
              // A new scene: set up its own two-level structure (the app's
              // structure is whatever the user chose; the animator needs a Tlas).
              s.animator.reset();
              s.tlas.reset();
              s.scene = r.scene;
              s.snap = std::make_shared<DynamicsSnapshot>();
              s.snap->scene = r.scene.get();
              s.snap->spec = r.scene->spec;
              s.snap->animates = scene_animates(r.scene->scene);
              s.snap->duration = animation_duration(r.scene->scene);
              {  // also when nothing animates but the user forced per-frame updates on
                const auto t0 = std::chrono::steady_clock::now();
                try {
                  TlasOptions to;
                  to.blas.compute_epo = false;
                  to.tlas = to.blas;
                  s.tlas = std::make_unique<Tlas>(r.scene->scene, to, [&](double) { return keep_going(); });
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
              // The frame for display: the scene posed at this time and the
              // chosen structure built over it (the app's build, as the
              // build worker makes it, but for this pose).
              const auto t0 = std::chrono::steady_clock::now();
              try {
                auto posed = std::make_shared<LoadedScene>();
                posed->spec = r.scene->spec;
                posed->scene = posed_scene(r.scene->scene, s.snap->history.back().time);
                StructureChoice choice = *r.structure;
                choice.options.scene = &posed->scene;
                std::shared_ptr<const Accelerator> accel = build_accelerator(
                    choice.name, posed->scene.triangles, choice.options, [&](double) { return keep_going(); });
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
