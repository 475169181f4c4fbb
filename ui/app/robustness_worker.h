#pragma once
// The Robustness panel's engine, GL-free: the robustness lab
// (core/analysis/robustness_lab.h) on the current scene, on a worker thread
// so the window never waits. A new request supersedes the one running (it is
// cancelled at the lab's next check); cancel() stops it.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "core/analysis/robustness_lab.h"
#include "ui/app/build_worker.h"
#include "ui/app/latest_job_worker.h"

namespace accelviz {

/// Whether the GUI's lab can also time the shown structure's own traversal:
/// the lab runs it over the scene's triangles, so not for voxels (their hits
/// are voxels) nor tlas (the lab's would be one instance of the triangles, not
/// the scene's instances). The panel's box is disabled and the request leaves
/// the structure out for these.
bool lab_times_own_traversal(std::string_view structure);

struct RobustnessRequest {
  std::shared_ptr<const LoadedScene> scene;  ///< kept alive while the lab runs
  LabOptions options;
};

struct RobustnessSnapshot {
  enum class State { running, done, cancelled, failed };
  std::uint64_t id = 0;
  State state = State::running;
  std::string scene;      ///< the scene's spec
  std::string structure;  ///< LabOptions::structure of the request
  std::string error;      ///< when failed: one line
  std::optional<LabResult> result;
};

class RobustnessWorker {
 public:
  RobustnessWorker();
  ~RobustnessWorker() = default;  ///< cancels and joins
  RobustnessWorker(const RobustnessWorker&) = delete;
  RobustnessWorker& operator=(const RobustnessWorker&) = delete;

  /// Replaces whatever is queued or running with `r`; returns its id.
  std::uint64_t request(RobustnessRequest r) { return worker_.request(std::move(r)); }
  void cancel() { worker_.cancel(); }
  /// The newest snapshot (null before the first request).
  std::shared_ptr<const RobustnessSnapshot> latest() const { return worker_.latest(); }
  bool busy() const { return worker_.busy(); }

 private:
  LatestJobWorker<RobustnessRequest, std::shared_ptr<const RobustnessSnapshot>> worker_;
};

}  // namespace accelviz
