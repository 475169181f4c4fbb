#include "ui/app/scenarios.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "core/accel/bvh/bvh.h"
#include "core/accel/factory.h"
#include "core/analysis/heatmap.h"
#include "core/query/camera.h"
#include "core/scene/load.h"
#include "core/util/timing.h"

namespace accelviz {

const std::vector<Scenario>& scenarios() {
  static const std::vector<Scenario> all = {
      {"teapot-stadium",
       "Teapot in a stadium",
       "A uniform grid sized to the scene's bounds puts the whole teapot in a few cells: as the stadium grows "
       "(slider), the grid's primitive tests per ray climb while the BVH and K-D tree barely move.",
       "stadium / teapot size",
       10.0f,
       100000.0f,
       1000.0f,
       true,
       {"grid", "bvh", "kdtree"}},
      {"walls",
       "Rotated walls",
       "The same walls, rotated about the vertical axis. Axis-aligned boxes around diagonal thin walls are mostly "
       "empty: the leaf boxes' volume and the BVH's cost per ray grow from 0 degrees to 45 and fall back at 90.",
       "rotation (degrees)",
       0.0f,
       90.0f,
       45.0f,
       false,
       {"bvh"}},
      {"same-centroid",
       "All primitives share one centroid (their vertices' average)",
       "The triangles' vertex averages are one point, but their boxes differ in size and centre, so the BVH "
       "(which bins box centres) still splits them; every box holds the common point, so the boxes overlap "
       "there and rays near it test many triangles; the K-D tree copies each reference into many cells. "
       "Compare 'one box for all', where binning has nothing to split. Watch cost per ray and depth as N grows "
       "(slider).",
       "triangles N",
       100.0f,
       20000.0f,
       2000.0f,
       true,
       {"bvh", "kdtree"}},
      {"same-bounds",
       "All primitives share one bounding box",
       "Every triangle has the same box: no box-based split separates anything, every node's box is the root's, "
       "so a ray enters (almost) every node it could. Watch cost per ray and depth as N grows (slider).",
       "triangles N",
       100.0f,
       20000.0f,
       2000.0f,
       true,
       {"bvh", "kdtree"}},
      {"grass",
       "Field of grass",
       "Uniformly spread thin blades at constant density: the case a uniform grid is made for. Compare its cost "
       "per ray and build time with the BVH's and the K-D tree's as the field grows (slider).",
       "triangles N",
       1000.0f,
       100000.0f,
       20000.0f,
       true,
       {"grid", "bvh", "kdtree"}},
      {"growth",
       "Growth with N",
       "Random triangle soup of constant density at N = largest/64, /16, /4 and largest (slider), nodes entered "
       "per ray against log N. Theory for a ray crossing the scene: a grid's cells grow as N^(1/3) (x4 for N "
       "x64), a BVH's depth as log N; a ray through a dense soup also enters many overlapping boxes, so compare "
       "the measured factors in the summary with both.",
       "largest N",
       4000.0f,
       64000.0f,
       16000.0f,
       true,
       {"grid", "bvh"}},
  };
  return all;
}

const Scenario* find_scenario(std::string_view id) {
  for (const Scenario& s : scenarios())
    if (s.id == id) return &s;
  return nullptr;
}

namespace {

float clamp_value(const Scenario& s, float v) {
  return std::clamp(std::isfinite(v) ? v : s.initial, s.min, s.max);
}

std::string scene_for(const std::string& id, float value, int size) {
  char buf[160];
  if (id == "teapot-stadium")
    std::snprintf(buf, sizeof buf, "builtin:teapot-stadium?size=%d&ratio=%.6g", size, static_cast<double>(value));
  else if (id == "walls")
    std::snprintf(buf, sizeof buf, "builtin:walls?size=%d&angle=%.6g", size, static_cast<double>(value));
  else if (id == "same-centroid" || id == "same-bounds" || id == "grass")
    std::snprintf(buf, sizeof buf, "builtin:%s?size=%d", id.c_str(), static_cast<int>(std::lround(value)));
  else  // growth
    std::snprintf(buf, sizeof buf, "builtin:soup?size=%d", size);
  return buf;
}

double leaf_volume_ratio(const Accelerator& a) {
  const auto* bvh = dynamic_cast<const Bvh*>(&a);
  if (!bvh || bvh->nodes().empty()) return 0.0;
  const auto volume = [](const Aabb& b) {
    const glm::vec3 e = glm::max(b.hi - b.lo, glm::vec3(0.0f));
    return static_cast<double>(e.x) * e.y * e.z;
  };
  const double root = volume(bvh->nodes()[0].bounds);
  if (!(root > 0.0)) return 0.0;
  double sum = 0.0;
  for (const BvhNode& n : bvh->nodes())
    if (n.is_leaf()) sum += volume(n.bounds);
  return sum / root;
}

ScenarioRow measure(const std::string& structure, const Scene& scene, const ScenarioRunOptions& o) {
  StructureOptions so;
  so.threads = o.threads;
  so.bvh.compute_epo = false;
  ProgressCallback keep_going;
  if (o.cancel) keep_going = [c = o.cancel](double) { return !c->load(); };
  const auto t0 = std::chrono::steady_clock::now();
  const std::unique_ptr<Accelerator> accel = build_accelerator(structure, scene.triangles, so, keep_going);
  ScenarioRow r;
  r.structure = structure;
  r.triangles = scene.triangles.size();
  r.build_ms = ms_since(t0);
  r.sah = accel->build_stats().sah_cost;
  r.max_depth = accel->build_stats().max_depth;
  r.leaf_volume_ratio = leaf_volume_ratio(*accel);
  const Camera cam = camera_from_spec("", scene, static_cast<float>(o.width) / static_cast<float>(o.height));
  HeatmapOptions ho{
      .metric = HeatMetric::nodes, .width = o.width, .height = o.height, .threads = o.threads, .progress = keep_going};
  HeatmapFigures f;
  render_metric(*accel, cam, ho, &f);
  r.nodes_per_ray = f.mean;
  ho.metric = HeatMetric::prims;
  render_metric(*accel, cam, ho, &f);
  r.prims_per_ray = f.mean;
  r.cost_per_ray = r.nodes_per_ray + r.prims_per_ray;
  return r;
}

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

}  // namespace

std::string scenario_scene(const Scenario& s, float value) {
  return scene_for(s.id, clamp_value(s, value), ScenarioRunOptions{}.scene_size);
}

ScenarioFigures run_scenario(const Scenario& s, float value, const ScenarioRunOptions& opts) {
  ScenarioFigures fig;
  fig.id = s.id;
  fig.value = clamp_value(s, value);
  if (s.id == "growth") {
    const int largest = static_cast<int>(std::lround(fig.value));
    for (const int div : {64, 16, 4, 1}) {
      const int n = std::max(16, largest / div);
      const std::string spec = scene_for(s.id, fig.value, n);
      const Scene scene = load_scene(spec);
      fig.scene = spec;
      for (const std::string& st : s.structures) fig.rows.push_back(measure(st, scene, opts));
    }
    // Growth factor of nodes per ray from the smallest to the largest N, per structure.
    for (const std::string& st : s.structures) {
      const ScenarioRow *first = nullptr, *last = nullptr;
      for (const ScenarioRow& r : fig.rows)
        if (r.structure == st) {
          if (!first) first = &r;
          last = &r;
        }
      if (first && last && first->nodes_per_ray > 0.0)
        fig.summary += st + " nodes/ray x" + fmt(last->nodes_per_ray / first->nodes_per_ray) + "  ";
    }
    if (!fig.rows.empty())
      fig.summary += "for N x" + fmt(static_cast<double>(fig.rows.back().triangles) /
                                     static_cast<double>(fig.rows.front().triangles));
    return fig;
  }
  fig.scene = scene_for(s.id, fig.value, opts.scene_size);
  const Scene scene = load_scene(fig.scene);
  for (const std::string& st : s.structures) fig.rows.push_back(measure(st, scene, opts));
  for (const ScenarioRow& r : fig.rows) fig.summary += r.structure + " cost/ray " + fmt(r.cost_per_ray) + "  ";
  return fig;
}

ScenarioJob::~ScenarioJob() {
  if (cancel_) cancel_->store(true);
  if (running_.valid()) running_.wait();
}

void ScenarioJob::request(const Scenario& s, float value, ScenarioRunOptions opts) {
  if (cancel_) cancel_->store(true);
  if (running_.valid()) running_.wait();  // a cancelled run stops within a chunk of rays
  cancel_ = std::make_shared<std::atomic<bool>>(false);
  opts.cancel = cancel_.get();
  running_ = std::async(std::launch::async, [s, value, opts, keep = cancel_] { return run_scenario(s, value, opts); });
}

void ScenarioJob::poll() {
  if (!running_.valid() || running_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
  try {
    figures_ = running_.get();
    error_.clear();
  } catch (const BuildCancelled&) {
  } catch (const std::exception& e) {
    error_ = e.what();
  }
}

bool ScenarioJob::busy() {
  poll();
  return running_.valid();
}

}  // namespace accelviz
