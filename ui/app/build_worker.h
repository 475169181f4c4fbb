#pragma once
// Loading and building off the main thread. One worker thread takes the
// newest request: asking for another structure while one is being built
// cancels the old build (its ProgressCallback answers false, the builder
// throws BuildCancelled) and starts the new one, so only the latest choice
// is ever waited for. Until a build succeeds the app keeps drawing and
// querying the structure it has: outcomes are handed over by value
// (shared_ptr), never swapped in behind the main thread's back.
#include <atomic>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "core/accel/accel.h"
#include "core/scene/effects.h"
#include "core/scene/scene.h"
#include "ui/app/app_config.h"
#include "ui/app/latest_job_worker.h"
#include "ui/app/structure_nodes.h"

namespace accelviz {

struct LoadedScene {
  std::string spec;  ///< as given to load_scene
  Scene scene;
  double load_ms = 0.0;
  /// Made in the app (a committed flatten), not loaded: `spec` names it but
  /// cannot be loaded again, so it is not remembered as the last or a recent scene.
  bool in_memory = false;
};

/// A finished build: the structure, the scene whose triangles it refers to
/// (kept alive with it), the choice it was built from and its node table.
struct BuiltStructure {
  std::shared_ptr<const LoadedScene> scene;
  std::shared_ptr<const Accelerator> accel;
  StructureChoice choice;
  StructureNodes nodes;
  double wall_ms = 0.0;  ///< build and node table, as the user waited for it
};

struct BuildRequest {
  std::string scene;  ///< scene spec; loaded unless it is the one loaded last (or `reload`)
  StructureChoice structure;
  bool reload = false;  ///< load the scene again even if it is the current one (File > Open of the same file)
  /// When set, this scene (spec == `scene`) is used instead of loading one.
  std::shared_ptr<const LoadedScene> preloaded;
  /// A scene opened by the user: its effects (decide_effects with `forces`)
  /// choose the level. A scene that instances a mesh more than once is built
  /// as `tlas` whatever `structure` names; one that does not, while
  /// `structure` is `tlas` and `single_level` names a structure (the one the
  /// app left for an instanced scene), is built as `single_level`.
  bool follow_effects = false;
  EffectForces forces;
  std::string single_level;
};

struct BuildOutcome {
  enum class Result { built, cancelled, failed };
  std::uint64_t id = 0;
  Result result = Result::failed;
  std::shared_ptr<const BuiltStructure> built;  ///< when built
  std::string error;                            ///< when failed: one line
  bool scene_error = false;                     ///< the failure was loading the scene
  /// The structure the request named when the scene's effects chose another
  /// (BuildRequest::follow_effects; built->choice names the one built); "" otherwise.
  std::string switched_from;
  std::string switch_reason;  ///< the two-level effect's reason, when switched
};

class BuildWorker {
 public:
  using LoadFn = std::function<Scene(const std::string& spec)>;
  using BuildFn = std::function<std::unique_ptr<Accelerator>(std::span<const Triangle>, const StructureChoice&,
                                                             const ProgressCallback&)>;
  /// Empty functions mean core's load_scene and build_accelerator; tests
  /// pass their own to control timing without sleeping.
  explicit BuildWorker(LoadFn load = {}, BuildFn build = {});
  ~BuildWorker() = default;  ///< cancels whatever runs and joins the thread
  BuildWorker(const BuildWorker&) = delete;
  BuildWorker& operator=(const BuildWorker&) = delete;

  /// Queues `r` as the next job, replacing a queued one and cancelling the
  /// one running. Returns its id (increasing from 1).
  std::uint64_t request(BuildRequest r) { return worker_.request(std::move(r)); }
  /// Cancels the queued and the running job.
  void cancel() { worker_.cancel(); }
  /// Outcomes finished since the last call, oldest first. A job superseded
  /// or cancelled (even one that finished while being cancelled) is reported
  /// as cancelled, never as built.
  std::vector<BuildOutcome> take_outcomes();

  struct Status {
    bool busy = false;      ///< a job is queued or running
    std::uint64_t id = 0;   ///< the running (or queued) job
    double fraction = 0.0;  ///< the builder's progress, 0..1
    std::string stage;      ///< "loading ...", "building bvh", ...
  };
  Status status() const;
  /// Nothing queued, nothing running, no outcome waiting to be taken.
  bool idle() const;
  std::uint64_t latest_request() const { return worker_.latest_request(); }

 private:
  BuildOutcome execute(std::uint64_t id, const BuildRequest& r);
  bool cancelled(std::uint64_t id) const { return worker_.cancelled(id); }
  void set_stage(std::string s);

  LoadFn load_;
  BuildFn build_;
  // Guarded by the worker's mutex (worker_.with_lock / its hooks):
  std::deque<BuildOutcome> outcomes_;
  std::string stage_;
  std::atomic<double> fraction_{0.0};
  std::shared_ptr<const LoadedScene> scene_;              ///< the last scene loaded (worker thread only)
  BuildOutcome done_;                                     ///< the job just run (worker thread only)
  LatestJobWorker<BuildRequest, std::monostate> worker_;  ///< last: joined before the members above go
};

}  // namespace accelviz
