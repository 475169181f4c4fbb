#include "ui/app/build_worker.h"

#include <algorithm>
#include <chrono>
#include <new>

#include "core/accel/factory.h"
#include "core/scene/load.h"
#include "core/util/one_line.h"
#include "core/util/timing.h"

namespace accelviz {
namespace {

BuildWorker::LoadFn default_load(BuildWorker::LoadFn load) {
  if (load) return load;
  return [](const std::string& spec) { return load_scene(spec); };
}

BuildWorker::BuildFn default_build(BuildWorker::BuildFn build) {
  if (build) return build;
  return [](std::span<const Triangle> tris, const StructureChoice& c, const ProgressCallback& progress) {
    return build_accelerator(c.name, tris, c.options, progress);
  };
}

}  // namespace

BuildWorker::BuildWorker(LoadFn load, BuildFn build)
    : load_(default_load(std::move(load))),
      build_(default_build(std::move(build))),
      worker_([this](const BuildRequest& r, std::uint64_t id, const std::function<bool()>&,
                     const std::function<void(std::monostate)>&) { done_ = execute(id, r); },
              {.dropped =
                   [this](std::uint64_t id, std::monostate&) {
                     outcomes_.push_back({id, BuildOutcome::Result::cancelled, nullptr, {}, false});
                   },
               .started =
                   [this](std::uint64_t) {
                     stage_ = "starting";
                     fraction_ = 0.0;
                   },
               .finished =
                   [this](std::uint64_t id) {
                     // A job that finished while it was being superseded does not count:
                     // the user has asked for something else meanwhile.
                     if (done_.result == BuildOutcome::Result::built && cancelled(id)) {
                       done_.result = BuildOutcome::Result::cancelled;
                       done_.built.reset();
                     }
                     outcomes_.push_back(std::move(done_));
                     done_ = {};
                   }}) {}

std::vector<BuildOutcome> BuildWorker::take_outcomes() {
  return worker_.with_lock([&](std::uint64_t, std::uint64_t) {
    std::vector<BuildOutcome> out(std::make_move_iterator(outcomes_.begin()), std::make_move_iterator(outcomes_.end()));
    outcomes_.clear();
    return out;
  });
}

BuildWorker::Status BuildWorker::status() const {
  return worker_.with_lock([&](std::uint64_t running, std::uint64_t queued) {
    Status s;
    if (running != 0) {
      s.busy = true;
      s.id = running;
      s.stage = stage_;
      s.fraction = fraction_.load();
    } else if (queued != 0) {
      s.busy = true;
      s.id = queued;
      s.stage = "queued";
    }
    return s;
  });
}

bool BuildWorker::idle() const {
  return worker_.with_lock(
      [&](std::uint64_t running, std::uint64_t queued) { return running == 0 && queued == 0 && outcomes_.empty(); });
}

void BuildWorker::set_stage(std::string s) {
  worker_.with_lock([&](std::uint64_t, std::uint64_t) {
    stage_ = std::move(s);
    fraction_ = 0.0;
  });
}

BuildOutcome BuildWorker::execute(std::uint64_t id, const BuildRequest& r) {
  BuildOutcome out;
  out.id = id;
  std::string building = r.structure.name;  // the structure built (the scene's effects may choose another)
  try {
    std::shared_ptr<const LoadedScene> scene = scene_;
    if (r.preloaded) {
      scene = r.preloaded;
      scene_ = scene;
    } else if (!scene || scene->spec != r.scene || r.reload) {
      set_stage("loading " + r.scene);
      const auto t0 = std::chrono::steady_clock::now();
      auto loaded = std::make_shared<LoadedScene>();
      loaded->spec = r.scene;
      try {
        loaded->scene = load_(r.scene);
      } catch (const std::bad_alloc&) {
        throw;
      } catch (const std::exception& e) {
        out.result = BuildOutcome::Result::failed;
        out.error = joined_line(e.what());
        out.scene_error = true;
        return out;
      }
      loaded->load_ms = ms_since(t0);
      scene = std::move(loaded);
      // Cached even if the build below fails: the next structure change
      // builds over the scene the user opened last.
      scene_ = scene;
    }
    if (cancelled(id)) throw BuildCancelled();
    StructureChoice wanted = r.structure;
    if (r.follow_effects) {
      const Effect two_level = decide_effects(scene->scene, r.forces).two_level;
      const std::string level = two_level.on                                       ? std::string("tlas")
                                : wanted.name == "tlas" && !r.single_level.empty() ? r.single_level
                                                                                   : wanted.name;
      if (level != wanted.name) {
        out.switched_from = wanted.name;
        out.switch_reason = two_level.reason;
        wanted.name = level;
      }
    }
    building = wanted.name;
    set_stage("building " + wanted.name);
    const auto t0 = std::chrono::steady_clock::now();
    const ProgressCallback progress = [this, id](double f) {
      fraction_ = std::clamp(f, 0.0, 1.0);
      return !cancelled(id);
    };
    StructureChoice choice = wanted;
    choice.options.scene = &scene->scene;  // "tlas": two levels from the scene's instances (used during the build only)
    std::shared_ptr<const Accelerator> accel = build_(scene->scene.triangles, choice, progress);
    if (cancelled(id)) throw BuildCancelled();
    set_stage("node table");
    auto built = std::make_shared<BuiltStructure>();
    built->nodes = StructureNodes::of(*accel);
    built->scene = std::move(scene);
    built->accel = std::move(accel);
    built->choice = wanted;
    built->wall_ms = ms_since(t0);
    out.result = BuildOutcome::Result::built;
    out.built = std::move(built);
  } catch (const BuildCancelled&) {
    out.result = BuildOutcome::Result::cancelled;
  } catch (const std::bad_alloc&) {
    out.result = BuildOutcome::Result::failed;
    out.error = "out of memory while building " + building;
  } catch (const std::exception& e) {
    out.result = BuildOutcome::Result::failed;
    out.error = building + ": " + joined_line(e.what());
  }
  return out;
}

}  // namespace accelviz
