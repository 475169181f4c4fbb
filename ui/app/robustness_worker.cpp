#include "ui/app/robustness_worker.h"

#include <exception>

namespace accelviz {

RobustnessWorker::RobustnessWorker() : thread_([this] { run(); }) {}

RobustnessWorker::~RobustnessWorker() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    queued_.reset();
  }
  cancel_upto_ = next_id_.load();
  wake_.notify_all();
  thread_.join();
}

std::uint64_t RobustnessWorker::request(RobustnessRequest r) {
  const std::uint64_t id = next_id_++;
  cancel_upto_ = id - 1;  // supersedes whatever runs
  auto snap = std::make_shared<RobustnessSnapshot>();
  snap->id = id;
  snap->scene = r.scene ? r.scene->spec : "";
  snap->structure = r.options.structure;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    queued_.emplace(id, std::move(r));
    latest_ = std::move(snap);
  }
  wake_.notify_all();
  return id;
}

void RobustnessWorker::cancel() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (queued_ && latest_ && latest_->id == queued_->first) {
      // Dropped before it started: its snapshot says so.
      auto snap = std::make_shared<RobustnessSnapshot>(*latest_);
      snap->state = RobustnessSnapshot::State::cancelled;
      latest_ = std::move(snap);
    }
    queued_.reset();
  }
  cancel_upto_ = next_id_.load();
}

std::shared_ptr<const RobustnessSnapshot> RobustnessWorker::latest() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return latest_;
}

bool RobustnessWorker::busy() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return running_ || queued_.has_value();
}

void RobustnessWorker::publish(std::shared_ptr<const RobustnessSnapshot> s) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!latest_ || latest_->id <= s->id) latest_ = std::move(s);
}

void RobustnessWorker::run() {
  for (;;) {
    std::pair<std::uint64_t, RobustnessRequest> job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      running_ = false;
      wake_.wait(lock, [this] { return stop_ || queued_.has_value(); });
      if (stop_) return;
      job = std::move(*queued_);
      queued_.reset();
      running_ = true;
    }
    const std::uint64_t id = job.first;
    auto snap = std::make_shared<RobustnessSnapshot>();
    snap->id = id;
    snap->scene = job.second.scene ? job.second.scene->spec : "";
    snap->structure = job.second.options.structure;
    try {
      if (!job.second.scene) throw std::invalid_argument("no scene");
      snap->result = run_robustness_lab(job.second.scene->scene.triangles, job.second.options,
                                        [this, id] { return cancel_upto_.load() < id; });
      snap->state = RobustnessSnapshot::State::done;
    } catch (const BuildCancelled&) {
      snap->state = RobustnessSnapshot::State::cancelled;
    } catch (const std::exception& e) {
      snap->state = RobustnessSnapshot::State::failed;
      snap->error = e.what();
    }
    publish(std::move(snap));
  }
}

}  // namespace accelviz
