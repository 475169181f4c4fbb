#include "ui/app/build_worker.h"

#include <algorithm>
#include <chrono>
#include <new>

#include "core/accel/factory.h"
#include "core/scene/load.h"

namespace accelviz {
namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  return s;
}

}  // namespace

BuildWorker::BuildWorker(LoadFn load, BuildFn build) : load_(std::move(load)), build_(std::move(build)) {
  if (!load_) load_ = [](const std::string& spec) { return load_scene(spec); };
  if (!build_)
    build_ = [](std::span<const Triangle> tris, const StructureChoice& c, const ProgressCallback& progress) {
      return build_accelerator(c.name, tris, c.options, progress);
    };
  thread_ = std::thread([this] { run(); });
}

BuildWorker::~BuildWorker() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
    queued_.reset();
  }
  cancel_upto_ = ~std::uint64_t{0};
  wake_.notify_all();
  thread_.join();
}

std::uint64_t BuildWorker::request(BuildRequest r) {
  std::uint64_t id;
  {
    std::lock_guard lock(mutex_);
    id = next_id_.fetch_add(1);
    if (queued_) outcomes_.push_back({queued_->first, BuildOutcome::Result::cancelled, nullptr, {}, false});
    queued_.emplace(id, std::move(r));
    // Everything older is superseded: the running build sees this in its
    // next progress call.
    cancel_upto_ = id - 1;
  }
  wake_.notify_all();
  return id;
}

void BuildWorker::cancel() {
  std::lock_guard lock(mutex_);
  if (queued_) {
    outcomes_.push_back({queued_->first, BuildOutcome::Result::cancelled, nullptr, {}, false});
    queued_.reset();
  }
  cancel_upto_ = next_id_.load() - 1;
}

std::vector<BuildOutcome> BuildWorker::take_outcomes() {
  std::lock_guard lock(mutex_);
  std::vector<BuildOutcome> out(std::make_move_iterator(outcomes_.begin()), std::make_move_iterator(outcomes_.end()));
  outcomes_.clear();
  return out;
}

BuildWorker::Status BuildWorker::status() const {
  std::lock_guard lock(mutex_);
  Status s;
  if (running_ != 0) {
    s.busy = true;
    s.id = running_;
    s.stage = stage_;
    s.fraction = fraction_.load();
  } else if (queued_) {
    s.busy = true;
    s.id = queued_->first;
    s.stage = "queued";
  }
  return s;
}

bool BuildWorker::idle() const {
  std::lock_guard lock(mutex_);
  return running_ == 0 && !queued_ && outcomes_.empty();
}

void BuildWorker::run() {
  for (;;) {
    std::pair<std::uint64_t, BuildRequest> job;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || queued_.has_value(); });
      if (stop_) return;
      job = std::move(*queued_);
      queued_.reset();
      running_ = job.first;
      stage_ = "starting";
      fraction_ = 0.0;
    }
    BuildOutcome outcome = execute(job.first, job.second);
    {
      std::lock_guard lock(mutex_);
      // A job that finished while it was being superseded does not count:
      // the user has asked for something else meanwhile.
      if (outcome.result == BuildOutcome::Result::built && cancelled(job.first)) {
        outcome.result = BuildOutcome::Result::cancelled;
        outcome.built.reset();
      }
      outcomes_.push_back(std::move(outcome));
      running_ = 0;
    }
  }
}

BuildOutcome BuildWorker::execute(std::uint64_t id, const BuildRequest& r) {
  BuildOutcome out;
  out.id = id;
  auto set_stage = [&](std::string s) {
    std::lock_guard lock(mutex_);
    stage_ = std::move(s);
    fraction_ = 0.0;
  };
  try {
    std::shared_ptr<const LoadedScene> scene = scene_;
    if (!scene || scene->spec != r.scene || r.reload) {
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
        out.error = one_line(e.what());
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
    set_stage("building " + r.structure.name);
    const auto t0 = std::chrono::steady_clock::now();
    const ProgressCallback progress = [this, id](double f) {
      fraction_ = std::clamp(f, 0.0, 1.0);
      return !cancelled(id);
    };
    StructureChoice choice = r.structure;
    choice.options.scene = &scene->scene;  // "tlas": two levels from the scene's instances (used during the build only)
    std::shared_ptr<const Accelerator> accel = build_(scene->scene.triangles, choice, progress);
    if (cancelled(id)) throw BuildCancelled();
    set_stage("node table");
    auto built = std::make_shared<BuiltStructure>();
    built->nodes = StructureNodes::of(*accel);
    built->scene = std::move(scene);
    built->accel = std::move(accel);
    built->choice = r.structure;
    built->wall_ms = ms_since(t0);
    out.result = BuildOutcome::Result::built;
    out.built = std::move(built);
  } catch (const BuildCancelled&) {
    out.result = BuildOutcome::Result::cancelled;
  } catch (const std::bad_alloc&) {
    out.result = BuildOutcome::Result::failed;
    out.error = "out of memory while building " + r.structure.name;
  } catch (const std::exception& e) {
    out.result = BuildOutcome::Result::failed;
    out.error = r.structure.name + ": " + one_line(e.what());
  }
  return out;
}

}  // namespace accelviz
