#include "ui/app/sweep_worker.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <stdexcept>

#include "core/accel/bvh/bvh.h"
#include "core/analysis/sah.h"
#include "core/query/ray_sets.h"
#include "core/util/timing.h"

namespace accelviz {

std::vector<SweepParam> parse_sweep_params_text(std::string_view structure, std::string_view text) {
  // As `accelviz sweep --structure` takes them: a tlas swept here measured one instance over the
  // flattened triangles, not the two-level structure shown.
  const std::vector<std::string>& sweepable = sweep_structures();
  if (std::find(sweepable.begin(), sweepable.end(), structure) == sweepable.end()) {
    std::string names;
    for (const std::string& s : sweepable) names += (names.empty() ? "" : ", ") + s;
    throw std::invalid_argument(std::string(structure) + " is not swept (the sweep measures " + names + ")");
  }
  std::vector<SweepParam> params;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && (text[i] == ' ' || text[i] == ';' || text[i] == '\t')) ++i;
    std::size_t j = i;
    while (j < text.size() && text[j] != ' ' && text[j] != ';' && text[j] != '\t') ++j;
    if (j > i) params.push_back(parse_sweep_param(text.substr(i, j - i)));
    i = j;
  }
  if (params.empty()) throw std::invalid_argument("sweep: no parameter given (expected NAME=V1,V2,...)");
  expand_sweep(structure, params);  // checks names, values and duplicates
  return params;
}

std::string default_sweep_params_text(std::string_view structure) {
  if (structure == "bvh") return "buckets=2,4,8,16,32,exact";
  if (structure == "kdtree") return "depth=8,12,16,20,0";
  if (structure == "grid") return "lambda=0.25,0.5,1,2,4,8";
  if (structure == "octree") return "depth=4,6,8,10";
  if (structure == "voxels") return "level=4,5,6,7,8";
  return "triangle=watertight,fast";
}

std::string apply_sweep_point(StructureChoice& choice, std::string_view structure, const SweepSetting& setting) {
  StructureChoice next = choice;
  next.name = std::string(structure);
  try {
    apply_sweep_setting(structure, setting, next.options, next.query);
  } catch (const std::exception& e) {
    return e.what();
  }
  choice = std::move(next);
  return {};
}

const char* sweep_figure_name(SweepFigure f) {
  switch (f) {
    case SweepFigure::sah_cost:
      return "SAH cost";
    case SweepFigure::rays_per_s:
      return "rays/s";
    case SweepFigure::nodes_per_ray:
      return "nodes/ray";
    case SweepFigure::prims_per_ray:
      return "triangle tests/ray";
    case SweepFigure::build_ms:
      return "build ms";
    case SweepFigure::total_ms:
      return "total ms (budget)";
    case SweepFigure::memory:
      return "memory MiB";
    case SweepFigure::edge_misses:
      return "edge misses";
  }
  return "?";
}

double sweep_figure_value(const SweepResult& r, SweepFigure f, double rays) {
  switch (f) {
    case SweepFigure::sah_cost:
      return r.sah_cost;
    case SweepFigure::rays_per_s:
      return r.rays_per_s;
    case SweepFigure::nodes_per_ray:
      return r.nodes_per_ray;
    case SweepFigure::prims_per_ray:
      return r.prims_per_ray;
    case SweepFigure::build_ms:
      return r.build_ms;
    case SweepFigure::total_ms:
      return r.total_ms(rays);
    case SweepFigure::memory:
      return static_cast<double>(r.memory_bytes) / (1024.0 * 1024.0);
    case SweepFigure::edge_misses:
      return static_cast<double>(r.edges.misses);
  }
  return 0.0;
}

std::vector<SweepSeries> sweep_series(std::span<const SweepResult> results, std::size_t param) {
  std::vector<SweepSeries> out;
  std::map<std::string, std::size_t> by_label;
  // Value order as first seen (the sweep lists each parameter's values in order).
  std::vector<std::string> values;
  for (std::size_t i = 0; i < results.size(); ++i) {
    const SweepSetting& s = results[i].setting;
    if (param >= s.size()) continue;
    SweepSetting others;
    for (std::size_t k = 0; k < s.size(); ++k)
      if (k != param) others.push_back(s[k]);
    const std::string label = others.empty() ? std::string() : setting_label(others);
    auto [it, fresh] = by_label.emplace(label, out.size());
    if (fresh) out.push_back({label, {}, {}});
    const std::string& v = s[param].second;
    auto vit = std::find(values.begin(), values.end(), v);
    if (vit == values.end()) vit = values.insert(values.end(), v);
    SweepSeries& series = out[it->second];
    series.value_index.push_back(static_cast<int>(vit - values.begin()));
    series.result.push_back(i);
  }
  return out;
}

double SweepSnapshot::fraction() const {
  const std::size_t steps = settings.size() + (calibration || stage == "calibrating" ? 1 : 0);
  if (state == State::done) return 1.0;
  const std::size_t done = results.size() + (calibration ? 1 : 0);
  const double within = done < settings.size() ? std::clamp(setting_fraction, 0.0, 1.0) : 0.0;
  return steps ? std::min(1.0, (static_cast<double>(done) + within) / static_cast<double>(steps)) : 0.0;
}

std::shared_ptr<const SweepSnapshot> run_sweep_request(
    const SweepRequest& r, std::uint64_t id, const std::function<bool()>& keep_going,
    const std::function<void(std::shared_ptr<const SweepSnapshot>)>& publish) {
  auto snap = std::make_shared<SweepSnapshot>();
  snap->id = id;
  snap->structure = r.structure;
  snap->params = r.params;
  auto emit = [&] {
    auto copy = std::make_shared<const SweepSnapshot>(*snap);
    if (publish) publish(copy);
    return copy;
  };
  try {
    if (!r.scene) throw std::runtime_error("no scene loaded");
    const std::vector<Triangle>& tris = r.scene->scene.triangles;
    snap->triangles = tris.size();
    snap->settings = expand_sweep(r.structure, r.params);
    bool sweeps_triangle = false;
    for (const SweepParam& p : r.params) sweeps_triangle |= p.name == "triangle";
    snap->stage = "making rays";
    emit();
    const std::vector<Ray> rays = primary_rays(r.camera, std::max(1, r.width), std::max(1, r.height));
    std::vector<EdgeProbe> probes;
    if (sweeps_triangle) probes = shared_edge_probes(tris, r.edge_probes, r.seed);
    snap->rays = rays.size();
    snap->probes = probes.size();
    SweepConfig cfg;
    cfg.structure = r.structure;
    cfg.base = r.base;
    cfg.query = r.query;
    cfg.repeat = r.repeat;
    cfg.threads = r.threads;
    cfg.keep_going = keep_going;
    // Inside a setting: a snapshot at most every 0.1 s, from whichever builder thread gets the lock
    // (the worker's own thread waits in measure_sweep_setting meanwhile and does not touch `snap`).
    std::mutex progress_mutex;
    std::chrono::steady_clock::time_point last_emit{};
    cfg.progress = [&](double f) {
      std::unique_lock lock(progress_mutex, std::try_to_lock);
      if (!lock.owns_lock()) return true;
      snap->setting_fraction = f;
      const auto now = std::chrono::steady_clock::now();
      if (now - last_emit >= std::chrono::milliseconds(100)) {
        last_emit = now;
        emit();
      }
      return true;
    };
    for (std::size_t i = 0; i < snap->settings.size(); ++i) {
      if (keep_going && !keep_going()) throw BuildCancelled();
      const SweepSetting& s = snap->settings[i];
      snap->stage = r.structure + " " + setting_label(s);
      snap->setting_fraction = 0;
      emit();
      const auto same = earlier_same_build(snap->settings, i);
      SweepResult m = measure_sweep_setting(tris, rays, probes, cfg, s, same ? &snap->results[*same] : nullptr);
      snap->results.push_back(std::move(m));
      snap->setting_fraction = 0;
    }
    if (r.calibrate) {
      snap->stage = "calibrating";
      emit();
      const Calibration c = calibrate(r.calibrate_options);
      if (keep_going && !keep_going()) throw BuildCancelled();
      snap->calibration = compare_calibrated_bvh(tris, rays, c, r.query, r.threads, r.repeat, keep_going);
    }
    snap->state = SweepSnapshot::State::done;
    snap->stage.clear();
  } catch (const BuildCancelled&) {
    snap->state = SweepSnapshot::State::cancelled;
    snap->stage.clear();
  } catch (const std::exception& e) {
    snap->state = SweepSnapshot::State::failed;
    snap->error = e.what();
    snap->stage.clear();
  }
  return emit();
}

namespace {

LatestJobWorker<SweepRequest, std::shared_ptr<const SweepSnapshot>>::Hooks sweep_hooks() {
  LatestJobWorker<SweepRequest, std::shared_ptr<const SweepSnapshot>>::Hooks h;
  // A request shows as running at once (a Cancel before it starts then has a snapshot to say so).
  h.queued = [](std::uint64_t id, const SweepRequest& r, std::shared_ptr<const SweepSnapshot>& latest) {
    auto snap = std::make_shared<SweepSnapshot>();
    snap->id = id;
    snap->structure = r.structure;
    snap->params = r.params;
    snap->stage = "queued";
    latest = std::move(snap);
  };
  h.store = [](std::uint64_t id, std::shared_ptr<const SweepSnapshot>&& s, bool superseded, bool newer_queued,
               std::shared_ptr<const SweepSnapshot>& latest) {
    // A superseded job's snapshots never replace a newer job's; its
    // own final "cancelled" snapshot is shown only if nothing newer is queued.
    if (!superseded || (!newer_queued && (!latest || latest->id <= id))) latest = std::move(s);
  };
  // Dropped before it started (cancelled, or replaced by a newer request): its snapshot says so.
  h.dropped = [](std::uint64_t id, std::shared_ptr<const SweepSnapshot>& latest) {
    if (latest && latest->id == id) {
      auto snap = std::make_shared<SweepSnapshot>(*latest);
      snap->state = SweepSnapshot::State::cancelled;
      snap->stage.clear();
      latest = std::move(snap);
    }
  };
  return h;
}

}  // namespace

SweepWorker::SweepWorker()
    : worker_(
          [](const SweepRequest& r, std::uint64_t id, const std::function<bool()>& keep_going,
             const std::function<void(std::shared_ptr<const SweepSnapshot>)>& publish) {
            run_sweep_request(r, id, keep_going, publish);
          },
          sweep_hooks()) {}

}  // namespace accelviz
