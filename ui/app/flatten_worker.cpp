#include "ui/app/flatten_worker.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "core/accel/tlas/flatten_json.h"
#include "core/util/one_line.h"
#include "core/util/timing.h"

namespace accelviz {

std::string flattened_spec(const std::string& spec, std::size_t merged) {
  return spec + " [flattened " + count_of(merged, "instance") + "]";
}

nlohmann::json flatten_result_json(const FlattenResult& r, const std::string& spec) {
  nlohmann::json j = {{"scene", spec},
                      {"instances", format_instance_ids(r.instances)},
                      {"width", r.width},
                      {"height", r.height},
                      {"ms", r.ms}};
  if (!r.error.empty()) j["error"] = r.error;
  if (r.figures) {
    j.update(flatten_what_if_json(*r.figures));
  }
  if (r.committed) j["committed"] = r.committed->spec;
  return j;
}

FlattenResult run_flatten_request(const FlattenRequest& r, const std::function<bool()>& keep_going,
                                  const std::function<void(double)>& fraction) {
  const auto t0 = std::chrono::steady_clock::now();
  FlattenResult out;
  out.kind = r.kind;
  out.scene = r.scene.get();
  out.instances = r.instances;
  out.width = r.width;
  out.height = r.height;
  if (!r.scene) throw std::invalid_argument("flatten: no scene");
  if (r.instances.empty()) throw std::invalid_argument("flatten: no instances selected");
  if (r.kind == FlattenRequest::Kind::preview) {
    out.figures = flatten_what_if(r.scene->scene, r.instances, r.camera, r.width, r.height, r.options, [&](double f) {
      if (fraction) fraction(f);
      return keep_going();
    });
  } else {
    if (!keep_going()) throw BuildCancelled();
    auto loaded = std::make_shared<LoadedScene>();
    FlattenedScene flat = flatten_instances(r.scene->scene, r.instances);
    if (!keep_going()) throw BuildCancelled();
    loaded->scene = std::move(flat.scene);
    loaded->spec = flattened_spec(r.scene->spec, r.instances.size());
    loaded->in_memory = true;
    if (fraction) fraction(1.0);
    out.committed = std::move(loaded);
  }
  out.ms = ms_since(t0);
  return out;
}

FlattenWorker::FlattenWorker()
    : worker_([this](const FlattenRequest& r, std::uint64_t id, const std::function<bool()>& keep_going,
                     const std::function<void(std::shared_ptr<const FlattenResult>)>& publish) {
        fraction_ = 0.0;
        auto result = std::make_shared<FlattenResult>();
        try {
          *result = run_flatten_request(r, keep_going, [this](double f) { fraction_ = f; });
        } catch (const BuildCancelled&) {
          return;  // superseded or cancelled: nothing to show
        } catch (const std::exception& e) {
          result->kind = r.kind;
          result->scene = r.scene.get();
          result->instances = r.instances;
          result->error = e.what();
        }
        result->id = id;
        publish(std::move(result));
      }) {}

}  // namespace accelviz
