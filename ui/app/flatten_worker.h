#pragma once
// The GUI's "flatten" what-if, GL-free (issue 10): which instances of the
// shown two-level scene to merge into one BLAS, the predicted cost of doing
// so measured off the UI thread (core's flatten_what_if: SAH, memory,
// nodes / triangle tests / instances per ray and trace ms on the same
// view, two-level vs merged), and the commit: the scene with those
// instances merged, as a new in-memory scene the build worker then builds
// the chosen structure over (AppState::open_loaded_scene).
//
// One job at a time on a LatestJobWorker ("latest job wins"): a new preview
// or commit supersedes the running one, which stops at its next progress
// check. Progress (fraction, stage) is readable from the UI thread at any time.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/accel/tlas/flatten_what_if.h"
#include "core/accel/tlas/instance_ids.h"
#include "ui/app/build_worker.h"
#include "ui/app/latest_job_worker.h"

namespace accelviz {

/// The spec the committed scene goes by: "SPEC [flattened N instances]".
/// It names an in-memory scene (LoadedScene::in_memory); it cannot be loaded again.
std::string flattened_spec(const std::string& spec, std::size_t merged);

struct FlattenRequest {
  enum class Kind { preview, commit };
  Kind kind = Kind::preview;
  std::shared_ptr<const LoadedScene> scene;
  std::vector<std::uint32_t> instances;  ///< ids into scene->scene.instances
  Camera camera;                         ///< preview: the view traced
  int width = 160, height = 120;         ///< preview: primary rays traced
  TlasOptions options;                   ///< both levels' BVH options
};

struct FlattenResult {
  std::uint64_t id = 0;
  FlattenRequest::Kind kind = FlattenRequest::Kind::preview;
  const LoadedScene* scene = nullptr;    ///< which scene it is of (identity only)
  std::vector<std::uint32_t> instances;  ///< what was merged
  int width = 0, height = 0;
  std::optional<FlattenWhatIf> figures;          ///< preview: done
  std::shared_ptr<const LoadedScene> committed;  ///< commit: the merged scene, ready to build
  double ms = 0.0;                               ///< wall time of the job
  std::string error;                             ///< one line, when it failed
};

/// A prediction's figures as JSON: scene, instances, rays (width, height),
/// merged_instances, merged_triangles, two_level and flattened (sah_cost,
/// memory_bytes, build_ms, instances, blas, rays, hits, mean_nodes,
/// mean_prims, mean_instances, trace_ms), ms; error when it failed.
nlohmann::json flatten_result_json(const FlattenResult& r, const std::string& spec);

/// Runs one request synchronously (the worker's job; exposed for tests).
/// KEEP_GOING is asked now and then (false: throws BuildCancelled);
/// FRACTION (optional) gets the progress 0..1.
FlattenResult run_flatten_request(const FlattenRequest& r, const std::function<bool()>& keep_going,
                                  const std::function<void(double)>& fraction = {});

class FlattenWorker {
 public:
  FlattenWorker();
  FlattenWorker(const FlattenWorker&) = delete;
  FlattenWorker& operator=(const FlattenWorker&) = delete;

  std::uint64_t request(FlattenRequest r) { return worker_.request(std::move(r)); }
  void cancel() { worker_.cancel(); }
  bool busy() const { return worker_.busy(); }
  /// The newest finished job's result (null before the first).
  std::shared_ptr<const FlattenResult> latest() const { return worker_.latest(); }
  std::uint64_t latest_request() const { return worker_.latest_request(); }
  /// Progress of the running job, 0..1.
  double fraction() const { return fraction_.load(); }

 private:
  std::atomic<double> fraction_{0.0};
  LatestJobWorker<FlattenRequest, std::shared_ptr<const FlattenResult>> worker_;  ///< last: joined first
};

}  // namespace accelviz
