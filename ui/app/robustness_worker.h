#pragma once
// The Robustness panel's engine, GL-free: the robustness lab
// (core/analysis/robustness_lab.h) on the current scene, on a worker thread
// so the window never waits. A new request supersedes the one running (it is
// cancelled at the lab's next check); cancel() stops it.
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "core/analysis/robustness_lab.h"
#include "ui/app/build_worker.h"

namespace accelviz {

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
  ~RobustnessWorker();  ///< cancels and joins
  RobustnessWorker(const RobustnessWorker&) = delete;
  RobustnessWorker& operator=(const RobustnessWorker&) = delete;

  /// Replaces whatever is queued or running with `r`; returns its id.
  std::uint64_t request(RobustnessRequest r);
  void cancel();
  /// The newest snapshot (null before the first request).
  std::shared_ptr<const RobustnessSnapshot> latest() const;
  bool busy() const;

 private:
  void run();
  void publish(std::shared_ptr<const RobustnessSnapshot> s);

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<std::pair<std::uint64_t, RobustnessRequest>> queued_;
  bool running_ = false;
  std::shared_ptr<const RobustnessSnapshot> latest_;
  std::atomic<std::uint64_t> next_id_{1};
  std::atomic<std::uint64_t> cancel_upto_{0};
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace accelviz
