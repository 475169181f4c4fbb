#pragma once
// "Latest job wins" on one background thread: the machinery the build,
// heatmap, sweep and robustness workers share. request() queues a job
// (replacing a queued one) and supersedes the one running: jobs with
// id <= cancel_upto_ see keep_going() turn false at their next check.
// What a job publishes is stored as `latest()` under the mutex, by the
// owner's rule (Hooks::store); the other hooks let an owner keep state of its
// own under the same mutex. Declare the worker as the owner's LAST member:
// it is built last (the thread may use the owner's other members) and
// destroyed first (the thread is joined before they go).
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

namespace accelviz {

template <class Request, class Result>
class LatestJobWorker {
 public:
  using KeepGoing = std::function<bool()>;
  using Publish = std::function<void(Result)>;
  /// Runs on the worker thread, without the mutex.
  using Job = std::function<void(const Request&, std::uint64_t id, const KeepGoing&, const Publish&)>;

  /// All run with the worker's mutex held.
  struct Hooks {
    /// Stores what job `id` published. `superseded`: a newer job was asked
    /// for (or cancel()); `newer_queued`: one is waiting. Default: `latest`
    /// takes it unless superseded.
    std::function<void(std::uint64_t id, Result&& published, bool superseded, bool newer_queued, Result& latest)> store;
    /// A job was queued (e.g. show it as running at once).
    std::function<void(std::uint64_t id, const Request&, Result& latest)> queued;
    /// A queued job was dropped before it started (replaced or cancelled).
    std::function<void(std::uint64_t id, Result& latest)> dropped;
    /// The thread picked up job `id`.
    std::function<void(std::uint64_t id)> started;
    /// Job `id` returned (in the same lock that marks the worker not running).
    std::function<void(std::uint64_t id)> finished;
  };

  explicit LatestJobWorker(Job job, Hooks hooks = {}) : job_(std::move(job)), hooks_(std::move(hooks)) {
    thread_ = std::thread([this] { run(); });
  }
  ~LatestJobWorker() {
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
      queued_.reset();
    }
    cancel_upto_ = ~std::uint64_t{0};
    wake_.notify_all();
    thread_.join();
  }
  LatestJobWorker(const LatestJobWorker&) = delete;
  LatestJobWorker& operator=(const LatestJobWorker&) = delete;

  /// Replaces whatever is queued or running with `r`; returns its id (increasing from 1).
  std::uint64_t request(Request r) {
    std::uint64_t id;
    {
      std::lock_guard lock(mutex_);
      id = next_id_.fetch_add(1);
      if (queued_ && hooks_.dropped) hooks_.dropped(queued_->first, latest_);
      queued_.emplace(id, std::move(r));
      // Everything older is superseded: the running job sees this at its next check.
      cancel_upto_ = id - 1;
      if (hooks_.queued) hooks_.queued(id, queued_->second, latest_);
    }
    wake_.notify_all();
    return id;
  }

  /// Stops the running job and drops the queued one.
  void cancel() {
    std::lock_guard lock(mutex_);
    if (queued_) {
      if (hooks_.dropped) hooks_.dropped(queued_->first, latest_);
      queued_.reset();
    }
    cancel_upto_ = next_id_.load() - 1;
  }

  Result latest() const {
    std::lock_guard lock(mutex_);
    return latest_;
  }
  /// A job is queued or running.
  bool busy() const {
    std::lock_guard lock(mutex_);
    return running_ != 0 || queued_.has_value();
  }
  std::uint64_t latest_request() const { return next_id_.load() - 1; }
  bool cancelled(std::uint64_t id) const { return id <= cancel_upto_.load(); }

  /// Runs f(running id, queued id) (0: none) with the mutex held, for state
  /// the owner keeps under the same lock.
  template <class F>
  decltype(auto) with_lock(F&& f) const {
    std::lock_guard lock(mutex_);
    return f(running_, queued_ ? queued_->first : std::uint64_t{0});
  }

 private:
  void run() {
    for (;;) {
      std::pair<std::uint64_t, Request> job;
      {
        std::unique_lock lock(mutex_);
        wake_.wait(lock, [&] { return stop_ || queued_.has_value(); });
        if (stop_) return;
        job = std::move(*queued_);
        queued_.reset();
        running_ = job.first;
        if (hooks_.started) hooks_.started(job.first);
      }
      const std::uint64_t id = job.first;
      job_(
          job.second, id, [&] { return id > cancel_upto_.load(std::memory_order_relaxed); },
          [&](Result r) {
            std::lock_guard lock(mutex_);
            const bool superseded = !(id > cancel_upto_.load());
            if (hooks_.store)
              hooks_.store(id, std::move(r), superseded, queued_.has_value(), latest_);
            else if (!superseded)
              latest_ = std::move(r);
          });
      {
        std::lock_guard lock(mutex_);
        if (hooks_.finished) hooks_.finished(id);
        running_ = 0;
      }
    }
  }

  Job job_;
  Hooks hooks_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<std::pair<std::uint64_t, Request>> queued_;
  std::uint64_t running_ = 0;  ///< id of the job running, 0 when none
  Result latest_{};
  std::atomic<std::uint64_t> next_id_{1};
  std::atomic<std::uint64_t> cancel_upto_{0};  ///< jobs with id <= this are cancelled
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace accelviz
