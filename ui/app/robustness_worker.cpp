#include "ui/app/robustness_worker.h"

#include <exception>

namespace accelviz {

bool lab_times_own_traversal(std::string_view structure) {
  return structure != "voxels" && structure != "tlas";
}

namespace {

using Worker = LatestJobWorker<RobustnessRequest, std::shared_ptr<const RobustnessSnapshot>>;

std::shared_ptr<RobustnessSnapshot> running_snapshot(std::uint64_t id, const RobustnessRequest& r) {
  auto snap = std::make_shared<RobustnessSnapshot>();
  snap->id = id;
  snap->scene = r.scene ? r.scene->spec : "";
  snap->structure = r.options.structure;
  return snap;
}

void run_lab(const RobustnessRequest& r, std::uint64_t id, const std::function<bool()>& keep_going,
             const std::function<void(std::shared_ptr<const RobustnessSnapshot>)>& publish) {
  auto snap = running_snapshot(id, r);
  try {
    if (!r.scene) throw std::invalid_argument("no scene");
    snap->result = run_robustness_lab(r.scene->scene.triangles, r.options, keep_going);
    snap->state = RobustnessSnapshot::State::done;
  } catch (const BuildCancelled&) {
    snap->state = RobustnessSnapshot::State::cancelled;
  } catch (const std::exception& e) {
    snap->state = RobustnessSnapshot::State::failed;
    snap->error = e.what();
  }
  publish(std::move(snap));
}

Worker::Hooks robustness_hooks() {
  Worker::Hooks h;
  // A request shows as running at once; a job's result never replaces a newer job's snapshot.
  h.queued = [](std::uint64_t id, const RobustnessRequest& r, std::shared_ptr<const RobustnessSnapshot>& latest) {
    latest = running_snapshot(id, r);
  };
  h.store = [](std::uint64_t id, std::shared_ptr<const RobustnessSnapshot>&& s, bool, bool,
               std::shared_ptr<const RobustnessSnapshot>& latest) {
    if (!latest || latest->id <= id) latest = std::move(s);
  };
  // Dropped before it started: its snapshot says so.
  h.dropped = [](std::uint64_t id, std::shared_ptr<const RobustnessSnapshot>& latest) {
    if (latest && latest->id == id) {
      auto snap = std::make_shared<RobustnessSnapshot>(*latest);
      snap->state = RobustnessSnapshot::State::cancelled;
      latest = std::move(snap);
    }
  };
  return h;
}

}  // namespace

RobustnessWorker::RobustnessWorker() : worker_(run_lab, robustness_hooks()) {}

}  // namespace accelviz
