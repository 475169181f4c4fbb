// Sweep expansion, measurement and the Pareto front (see sweep.h).
#include "core/analysis/sweep.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "core/accel/bvh/bvh.h"
#include "core/analysis/sah.h"
#include "core/query/batch.h"
#include "core/scene/effects.h"
#include "core/util/parallel.h"
#include "core/util/random.h"
#include "core/util/timing.h"

namespace accelviz {

namespace {

[[noreturn]] void bad_value(const std::string& name, const std::string& value, const std::string& why) {
  throw std::invalid_argument("sweep parameter " + name + ": bad value '" + value + "' (" + why + ")");
}

/// The whole of `v` as a T, or bad_value saying `expected` (from_chars for floating point is in
/// GCC 12's libstdc++; strtof would accept "1x").
template <class T>
T parse_number(const std::string& name, const std::string& v, const std::string& expected) {
  T out{};
  const auto [p, ec] = std::from_chars(v.data(), v.data() + v.size(), out);
  if (ec != std::errc() || p != v.data() + v.size()) bad_value(name, v, expected);
  return out;
}

int parse_int(const std::string& name, const std::string& v, int lo, int hi) {
  const std::string range = std::to_string(lo) + ".." + std::to_string(hi);
  const int out = parse_number<int>(name, v, "expected an integer " + range);
  if (out < lo || out > hi) bad_value(name, v, "expected " + range);
  return out;
}

float parse_positive(const std::string& name, const std::string& v) {
  const float out = parse_number<float>(name, v, "expected a finite number > 0");
  if (!std::isfinite(out) || out <= 0) bad_value(name, v, "expected a finite number > 0");
  return out;
}

/// An SAH cost constant: a number in the range the command line takes (cost_constant_problem).
float parse_cost(const std::string& name, const std::string& v) {
  const double out = parse_number<double>(name, v, "expected a number from 1e-06 to 1e+06");
  if (const std::string problem = cost_constant_problem(out); !problem.empty()) bad_value(name, v, problem);
  return static_cast<float>(out);
}

bool parse_on_off(const std::string& name, const std::string& v) {
  if (v == "on") return true;
  if (v == "off") return false;
  bad_value(name, v, "expected on or off");
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const std::string& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

}  // namespace

std::string setting_label(const SweepSetting& setting) {
  std::string s;
  for (const auto& [k, v] : setting) s += (s.empty() ? "" : " ") + k + "=" + v;
  return s.empty() ? "default" : s;
}

const std::vector<std::string>& sweep_structures() {
  static const std::vector<std::string> names{"bvh", "kdtree", "grid", "octree", "voxels"};
  return names;
}

const std::vector<std::string>& sweep_param_names(std::string_view structure) {
  static const std::map<std::string, std::vector<std::string>, std::less<>> names{
      {"bvh", {"buckets", "splitter", "leaf", "ctrav", "cisect", "triangle"}},
      {"kdtree", {"depth", "ctrav", "cisect", "leaf", "mailbox", "triangle"}},
      {"grid", {"lambda", "res", "triangle"}},
      {"octree", {"depth", "leaf", "triangle"}},
      {"voxels", {"level", "triangle"}},
  };
  static const std::vector<std::string> only_triangle{"triangle"};
  const auto it = names.find(structure);
  return it == names.end() ? only_triangle : it->second;
}

bool sweep_param_is_query(std::string_view name) {
  return name == "triangle";
}

std::optional<std::size_t> earlier_same_build(std::span<const SweepSetting> settings, std::size_t i) {
  const auto build_part = [](const SweepSetting& s) {
    SweepSetting b;
    for (const auto& kv : s)
      if (!sweep_param_is_query(kv.first)) b.push_back(kv);
    return b;
  };
  const SweepSetting mine = build_part(settings[i]);
  for (std::size_t j = 0; j < i; ++j)
    if (build_part(settings[j]) == mine) return j;
  return std::nullopt;
}

SweepParam parse_sweep_param(std::string_view text) {
  const std::size_t eq = text.find('=');
  if (eq == std::string_view::npos || eq == 0)
    throw std::invalid_argument("sweep parameter '" + std::string(text) + "': expected NAME=V1,V2,...");
  SweepParam p;
  p.name = std::string(text.substr(0, eq));
  std::string rest(text.substr(eq + 1));
  std::stringstream ss(rest);
  std::string v;
  while (std::getline(ss, v, ',')) {
    if (v.empty()) throw std::invalid_argument("sweep parameter " + p.name + ": empty value in '" + rest + "'");
    p.values.push_back(v);
  }
  if (p.values.empty() || rest.back() == ',')
    throw std::invalid_argument("sweep parameter " + p.name + ": no values (expected " + p.name + "=V1,V2,...)");
  return p;
}

void apply_sweep_setting(std::string_view structure, const SweepSetting& setting, StructureOptions& o,
                         QueryOptions& q) {
  const std::vector<std::string>& valid = sweep_param_names(structure);
  for (const auto& [name, v] : setting) {
    if (std::find(valid.begin(), valid.end(), name) == valid.end())
      throw std::invalid_argument("unknown sweep parameter '" + name + "' for " + std::string(structure) +
                                  " (valid: " + joined(valid) + ")");
    if (name == "triangle") {
      if (v == "watertight")
        q.triangle_test = TriangleTest::watertight;
      else if (v == "fast")
        q.triangle_test = TriangleTest::moller_trumbore;
      else
        bad_value(name, v, "expected watertight or fast");
    } else if (structure == "bvh") {
      if (name == "buckets") {
        if (v == "exact") {
          o.bvh.splitter = BvhSplitter::exact_sah;
        } else {
          o.bvh.buckets = parse_int(name, v, 2, 256);
          o.bvh.splitter = BvhSplitter::binned_sah;
        }
      } else if (name == "splitter") {
        if (v == "median")
          o.bvh.splitter = BvhSplitter::median;
        else if (v == "binned")
          o.bvh.splitter = BvhSplitter::binned_sah;
        else if (v == "exact")
          o.bvh.splitter = BvhSplitter::exact_sah;
        else if (v == "lbvh")
          o.bvh.splitter = BvhSplitter::lbvh;
        else
          bad_value(name, v, "expected median, binned, exact or lbvh");
      } else if (name == "leaf") {
        o.bvh.max_leaf_size = parse_int(name, v, 1, 255);
        o.bvh.leaf_size_cap = std::max(o.bvh.leaf_size_cap, o.bvh.max_leaf_size);
      } else if (name == "ctrav") {
        o.bvh.cost_traversal = parse_cost(name, v);
      } else if (name == "cisect") {
        o.bvh.cost_intersect = parse_cost(name, v);
      }
    } else if (structure == "kdtree") {
      if (name == "depth")
        o.kdtree.max_depth = parse_int(name, v, 0, 64);
      else if (name == "ctrav")
        o.kdtree.cost_traversal = parse_cost(name, v);
      else if (name == "cisect")
        o.kdtree.cost_intersect = parse_cost(name, v);
      else if (name == "leaf")
        o.kdtree.max_leaf_size = parse_int(name, v, 1, 1 << 20);
      else if (name == "mailbox")
        o.kdtree.mailboxing = parse_on_off(name, v);
    } else if (structure == "grid") {
      if (name == "lambda") {
        o.grid.lambda = parse_positive(name, v);
        o.grid.resolution = {0, 0, 0};
      } else if (name == "res") {
        std::array<int, 3> r{};
        std::stringstream ss(v);
        std::string part;
        int k = 0;
        while (std::getline(ss, part, 'x')) {
          if (k == 3) bad_value(name, v, "expected NXxNYxNZ");
          r[k++] = parse_int(name, part, 1, 4096);
        }
        if (k != 3) bad_value(name, v, "expected NXxNYxNZ, e.g. 16x16x16");
        if (static_cast<std::uint64_t>(r[0]) * static_cast<std::uint64_t>(r[1]) * static_cast<std::uint64_t>(r[2]) >
            kGridMaxCells)
          bad_value(name, v, "more than 2^26 cells");
        o.grid.resolution = r;
      }
    } else if (structure == "octree") {
      if (name == "depth")
        o.octree.max_depth = parse_int(name, v, 0, 16);
      else if (name == "leaf")
        o.octree.max_leaf_size = parse_int(name, v, 1, 1 << 20);
    } else if (structure == "voxels") {
      if (name == "level") o.voxels.level = parse_int(name, v, 0, 10);
    }
  }
  if (structure == "bvh") validate(o.bvh);
}

std::vector<SweepSetting> expand_sweep(std::string_view structure, std::span<const SweepParam> params) {
  std::set<std::string> seen;
  for (const SweepParam& p : params) {
    if (!seen.insert(p.name).second) throw std::invalid_argument("sweep parameter " + p.name + " given twice");
    if (p.values.empty()) throw std::invalid_argument("sweep parameter " + p.name + ": no values");
    // Check every value on its own, so the message names the first bad one.
    for (const std::string& v : p.values) {
      StructureOptions o;
      QueryOptions q;
      apply_sweep_setting(structure, {{p.name, v}}, o, q);
    }
  }
  // A fixed resolution leaves lambda nothing to choose: each lambda would be the same grid under
  // another label.
  if (structure == "grid" && seen.count("lambda") && seen.count("res"))
    throw std::invalid_argument("sweep parameters lambda and res together: a fixed resolution (res) ignores lambda");
  // Counted before they are made: 2e14 combinations filled 8 GB before the first build.
  double count = 1.0;
  std::string product;
  for (const SweepParam& p : params) {
    count *= static_cast<double>(p.values.size());
    product += (product.empty() ? "" : " x ") + std::to_string(p.values.size());
  }
  if (count > static_cast<double>(kMaxSweepSettings)) {
    char n[32];
    std::snprintf(n, sizeof n, "%.4g", count);
    throw std::invalid_argument("sweep parameters give " + std::string(n) + " settings (" + product +
                                " values), more than the " + std::to_string(kMaxSweepSettings) +
                                " one sweep takes: give fewer values");
  }
  std::vector<SweepSetting> out{SweepSetting{}};
  for (const SweepParam& p : params) {
    std::vector<SweepSetting> next;
    for (const SweepSetting& s : out)
      for (const std::string& v : p.values) {
        SweepSetting t = s;
        t.emplace_back(p.name, v);
        next.push_back(std::move(t));
      }
    out = std::move(next);
  }
  return out;
}

// ---- shared-edge probes ------------------------------------------------------------

std::vector<EdgeProbe> shared_edge_probes(std::span<const Triangle> triangles, std::size_t max_probes,
                                          std::uint64_t seed) {
  // Edges keyed by their two end positions (exact floats, ordered), so
  // welded meshes match across triangles without an index buffer.
  using Key = std::array<float, 6>;
  auto key = [](glm::vec3 a, glm::vec3 b) {
    if (std::tie(b.x, b.y, b.z) < std::tie(a.x, a.y, a.z)) std::swap(a, b);
    return Key{a.x, a.y, a.z, b.x, b.y, b.z};
  };
  std::map<Key, std::vector<std::uint32_t>> edges;
  for (std::uint32_t i = 0; i < triangles.size(); ++i) {
    const Triangle& t = triangles[i];
    if (t.area() <= 0.0f) continue;
    edges[key(t.v0, t.v1)].push_back(i);
    edges[key(t.v1, t.v2)].push_back(i);
    edges[key(t.v2, t.v0)].push_back(i);
  }
  std::vector<std::pair<Key, std::array<std::uint32_t, 2>>> shared;
  for (const auto& [k, tris] : edges)
    if (tris.size() == 2 && tris[0] != tris[1]) shared.push_back({k, {tris[0], tris[1]}});
  if (shared.empty() || max_probes == 0) return {};

  Aabb box = Aabb::empty();
  for (const Triangle& t : triangles) box.extend(t.bounds());
  const float diag = glm::length(box.extent());
  const std::size_t n = std::min(max_probes, shared.size());
  std::vector<EdgeProbe> out;
  out.reserve(n);
  SplitMix64 rng(seed);
  for (std::size_t k = 0; k < n; ++k) {
    const auto& [e, tris] = shared[k * shared.size() / n];
    const glm::vec3 a(e[0], e[1], e[2]), b(e[3], e[4], e[5]);
    const glm::vec3 target = a + 0.5f * (b - a);
    // A uniform direction on the sphere, redrawn until the two triangles'
    // third vertices project to opposite sides of the edge as seen along it:
    // only then must a ray through the edge hit one of them (seen edge-on, as
    // a silhouette fold, it may rightly miss both). The origin sits outside
    // the scene box.
    auto third = [&](std::uint32_t t) {
      const Triangle& tri = triangles[t];
      for (const glm::vec3& v : {tri.v0, tri.v1, tri.v2})
        if (v != a && v != b) return v;
      return tri.v0;
    };
    const glm::vec3 ca = third(tris[0]), cb = third(tris[1]);
    glm::vec3 dir(0.0f);
    bool found = false;
    for (int attempt = 0; attempt < 32 && !found; ++attempt) {
      const double z = 2.0 * rng.uniform_double() - 1.0, phi = 6.283185307179586 * rng.uniform_double();
      const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
      dir = glm::vec3(static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)),
                      static_cast<float>(z));
      const glm::vec3 e = b - a;
      const float sa = glm::dot(glm::cross(e, ca - a), dir), sb = glm::dot(glm::cross(e, cb - a), dir);
      found = (sa > 0 && sb < 0) || (sa < 0 && sb > 0);
    }
    if (!found) continue;
    EdgeProbe p;
    p.ray = Ray(target - dir * (2.0f * diag), dir);
    p.tri_a = tris[0];
    p.tri_b = tris[1];
    out.push_back(p);
  }
  return out;
}

EdgeLeaks count_edge_leaks(std::span<const Triangle> triangles, std::span<const EdgeProbe> probes, TriangleTest test) {
  EdgeLeaks r;
  r.probes = probes.size();
  for (const EdgeProbe& p : probes) {
    const WatertightRay wr(p.ray.direction);
    Hit ha, hb;
    const bool a = intersect_triangle(test, p.ray, wr, triangles[p.tri_a], p.ray.tmin, p.ray.tmax, ha);
    const bool b = intersect_triangle(test, p.ray, wr, triangles[p.tri_b], p.ray.tmin, p.ray.tmax, hb);
    r.misses += !a && !b;
    r.double_hits += a && b;
  }
  return r;
}

std::vector<std::array<std::uint32_t, 3>> shared_edge_neighbours(std::span<const Triangle> triangles) {
  using Key = std::array<float, 6>;
  auto key = [](glm::vec3 a, glm::vec3 b) {
    if (std::tie(b.x, b.y, b.z) < std::tie(a.x, a.y, a.z)) std::swap(a, b);
    return Key{a.x, a.y, a.z, b.x, b.y, b.z};
  };
  std::map<Key, std::vector<std::pair<std::uint32_t, int>>> edges;
  for (std::uint32_t i = 0; i < triangles.size(); ++i) {
    const Triangle& t = triangles[i];
    if (t.area() <= 0.0f) continue;
    edges[key(t.v0, t.v1)].push_back({i, 0});
    edges[key(t.v1, t.v2)].push_back({i, 1});
    edges[key(t.v2, t.v0)].push_back({i, 2});
  }
  std::vector<std::array<std::uint32_t, 3>> out(triangles.size(), {kInvalidId, kInvalidId, kInvalidId});
  for (const auto& [k, v] : edges)
    if (v.size() == 2 && v[0].first != v[1].first) {
      out[v[0].first][v[0].second] = v[1].first;
      out[v[1].first][v[1].second] = v[0].first;
    }
  return out;
}

std::uint64_t count_ray_double_hits(std::span<const Triangle> triangles,
                                    std::span<const std::array<std::uint32_t, 3>> neighbours, std::span<const Ray> rays,
                                    std::span<const Hit> hits, TriangleTest test) {
  std::uint64_t n = 0;
  for (std::size_t i = 0; i < rays.size() && i < hits.size(); ++i) {
    const Hit& h = hits[i];
    if (!h.valid() || h.prim >= neighbours.size()) continue;
    const WatertightRay wr(rays[i].direction);
    for (const std::uint32_t o : neighbours[h.prim]) {
      if (o == kInvalidId) continue;
      Hit other;
      if (intersect_triangle(test, rays[i], wr, triangles[o], rays[i].tmin, rays[i].tmax, other) &&
          std::fabs(other.t - h.t) <= 1e-5f * std::max(1.0f, h.t)) {
        ++n;
        break;
      }
    }
  }
  return n;
}

// ---- measuring ---------------------------------------------------------------------

TimedStructure time_structure(
    const std::function<std::unique_ptr<Accelerator>(const ProgressCallback& progress)>& build,
    std::span<const Ray> rays, const QueryOptions& query, unsigned threads, int warmup, int repeat,
    const std::function<bool()>& keep_going, bool time_builds, const ProgressCallback& report) {
  const auto check = [&] {
    if (keep_going && !keep_going()) throw BuildCancelled();
  };
  // Steps: each build and each pass (the warm-up rounds' passes, the timed ones and the counting one),
  // weighed by how long a build and a pass take, as measured so far: with -n 100, quick builds and
  // slow passes are not half of the time as they are half of the steps. Until a kind has been
  // measured it weighs as much as the other (as 1 when neither has).
  const int warmups = std::max(0, warmup);
  const int timed_builds = time_builds ? std::max(1, repeat) : warmups > 0 ? 0 : 1;
  const int passes = rays.empty() ? 0 : warmups + std::max(1, repeat) + 1;
  // Changed only between builds and passes (no builder thread reads them then).
  int builds_done = 0, passes_done = 0;
  double build_s = 0, pass_s = 0;  ///< total seconds of the finished builds and passes
  bool in_build = true;            ///< the kind of the step under way
  std::mutex report_mutex;         ///< builder threads report too: one at a time, in order
  double reported = 0;             ///< the largest fraction reported: the next is never less
  auto step_start = std::chrono::steady_clock::now();
  const auto fraction = [&](double of_current) {
    const double b = builds_done ? build_s / builds_done : passes_done ? pass_s / passes_done : 1.0;
    const double p = passes_done ? pass_s / passes_done : b;
    const double total = (warmups + timed_builds) * b + passes * p;
    const double done = builds_done * b + passes_done * p + of_current * (in_build ? b : p);
    return total > 0 ? std::min(1.0, done / total) : 1.0;
  };
  // Weights change as steps are measured, so a fraction may come out below the last one told.
  const auto tell = [&](double f) {
    const std::lock_guard lock(report_mutex);
    reported = std::max(reported, f);
    report(reported);
  };
  const auto step_done = [&](bool was_build) {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - step_start).count();
    (was_build ? build_s : pass_s) += std::max(s, 1e-9);  // a step never weighs nothing
    ++(was_build ? builds_done : passes_done);
    step_start = now;
    if (report) tell(fraction(0));
  };
  const auto begin = [&](bool build_step) {
    in_build = build_step;
    step_start = std::chrono::steady_clock::now();
  };
  const bool kBuild = true, kPass = false;
  ProgressCallback progress;
  if (keep_going || report)
    progress = [&](double f) {
      if (report) tell(fraction(std::clamp(f, 0.0, 1.0)));
      return !keep_going || keep_going();
    };
  const unsigned n_threads = resolve_threads(threads);
  TimedStructure t;
  t.hits.resize(rays.size());
  for (int k = 0; k < warmups; ++k) {
    t.accel.reset();  // never two copies in memory
    check();
    begin(kBuild);
    t.accel = build(progress);
    step_done(kBuild);
    check();
    if (!rays.empty()) {
      begin(kPass);
      trace_closest(*t.accel, rays, t.hits, query, n_threads);
      step_done(kPass);
    }
  }
  for (int k = 0; k < timed_builds; ++k) {
    t.accel.reset();
    check();
    begin(kBuild);
    t.accel = build(progress);
    step_done(kBuild);
    if (time_builds) t.build_ms_runs.push_back(t.accel->build_stats().build_ms);
  }
  if (rays.empty()) return t;
  for (int k = 0; k < std::max(1, repeat); ++k) {
    check();
    begin(kPass);
    const auto t0 = std::chrono::steady_clock::now();
    trace_closest(*t.accel, rays, t.hits, query, n_threads);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    t.rays_per_s_runs.push_back(s > 0 ? static_cast<double>(rays.size()) / s : 0.0);
    step_done(kPass);
  }
  check();
  begin(kPass);
  std::vector<RayStats> stats(rays.size());
  trace_closest(*t.accel, rays, t.hits, query, n_threads, stats);
  step_done(kPass);
  double nodes = 0, prims = 0, hit_count = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    nodes += stats[i].nodes_visited;
    prims += stats[i].prim_tests;
    hit_count += t.hits[i].valid();
  }
  const double n = static_cast<double>(rays.size());
  t.nodes_per_ray = nodes / n;
  t.prims_per_ray = prims / n;
  t.hit_fraction = hit_count / n;
  return t;
}

namespace {

CalibratedTree measure_tree(std::span<const Triangle> triangles, std::span<const Ray> rays, float ctrav, float cisect,
                            double judge_cisect, const QueryOptions& q, unsigned threads, int repeat,
                            const std::function<bool()>& keep_going) {
  BvhOptions o;
  o.cost_traversal = ctrav;
  o.cost_intersect = cisect;
  o.compute_epo = false;
  o.threads = threads;
  // One untimed round first: the tree measured first must not pay for the
  // memory its builds touch first (the default tree, built first, read twice
  // the calibrated one's build time on the same teapot).
  const TimedStructure timed =
      time_structure([&](const ProgressCallback& progress) { return std::make_unique<Bvh>(triangles, o, progress); },
                     rays, q, threads, /*warmup=*/1, repeat, keep_going);
  const Bvh& bvh = dynamic_cast<const Bvh&>(*timed.accel);
  CalibratedTree t;
  t.c_trav = ctrav;
  t.c_isect = cisect;
  t.build_ms = median(timed.build_ms_runs);
  t.nodes = bvh.build_stats().node_count;
  t.sah_own = bvh.build_stats().sah_cost;
  t.sah_calibrated = bvh_sah_cost(bvh.nodes(), 1.0, judge_cisect);
  t.rays_per_s = median(timed.rays_per_s_runs);
  t.nodes_per_ray = timed.nodes_per_ray;
  t.prims_per_ray = timed.prims_per_ray;
  return t;
}

}  // namespace

CalibrationReport compare_calibrated_bvh(std::span<const Triangle> triangles, std::span<const Ray> rays,
                                         const Calibration& c, const QueryOptions& query, unsigned threads, int repeat,
                                         const std::function<bool()>& keep_going) {
  CalibrationReport r;
  r.machine = c;
  r.c_isect = query.triangle_test == TriangleTest::watertight ? c.c_isect_watertight() : c.c_isect_fast();
  if (!(r.c_isect > 0) || !std::isfinite(r.c_isect))
    throw std::runtime_error("calibration gave no usable C_isect (box test time 0?)");
  r.with_default = measure_tree(triangles, rays, 1.0f, 1.0f, r.c_isect, query, threads, repeat, keep_going);
  r.with_calibrated =
      measure_tree(triangles, rays, 1.0f, static_cast<float>(r.c_isect), r.c_isect, query, threads, repeat, keep_going);
  return r;
}

SweepResult measure_sweep_setting(std::span<const Triangle> triangles, std::span<const Ray> rays,
                                  std::span<const EdgeProbe> probes, const SweepConfig& config,
                                  const SweepSetting& setting, const SweepResult* same_build) {
  SweepResult r;
  r.setting = setting;
  StructureOptions so = config.base;
  QueryOptions q = config.query;
  apply_sweep_setting(config.structure, setting, so, q);
  so.threads = config.threads;
  so.bvh.threads = config.threads;
  r.triangle_test = q.triangle_test == TriangleTest::watertight ? "watertight" : "fast";
  TimedStructure t = time_structure(
      [&](const ProgressCallback& progress) { return build_accelerator(config.structure, triangles, so, progress); },
      rays, q, config.threads, config.warmup, config.repeat, config.keep_going, same_build == nullptr, config.progress);
  if (same_build) {
    r.build_of = same_build->build_of.empty() ? setting_label(same_build->setting) : same_build->build_of;
    r.build_ms_runs = same_build->build_ms_runs;
    r.build_ms = same_build->build_ms;
    r.memory_bytes = same_build->memory_bytes;
    r.nodes = same_build->nodes;
    r.leaves = same_build->leaves;
    r.max_depth = same_build->max_depth;
    r.sah_cost = same_build->sah_cost;
    r.epo = same_build->epo;
  } else {
    r.build_ms_runs = std::move(t.build_ms_runs);
    r.build_ms = median(r.build_ms_runs);
    const BuildStats& bs = t.accel->build_stats();
    r.memory_bytes = bs.memory_bytes;
    r.nodes = bs.node_count;
    r.leaves = bs.leaf_count;
    r.max_depth = bs.max_depth;
    r.sah_cost = bs.sah_cost;
    if (const auto it = bs.extra.find("epo"); it != bs.extra.end()) r.epo = it->second;
  }

  if (!rays.empty()) {
    r.rays_per_s_runs = std::move(t.rays_per_s_runs);
    r.rays_per_s = median(r.rays_per_s_runs);
    r.nodes_per_ray = t.nodes_per_ray;
    r.prims_per_ray = t.prims_per_ray;
    r.hit_fraction = t.hit_fraction;
    if (!probes.empty())
      r.ray_double_hits =
          count_ray_double_hits(triangles, shared_edge_neighbours(triangles), rays, t.hits, q.triangle_test);
  }
  if (!probes.empty()) r.edges = count_edge_leaks(triangles, probes, q.triangle_test);
  return r;
}

std::vector<SweepResult> run_sweep(std::span<const Triangle> triangles, std::span<const Ray> rays,
                                   std::span<const EdgeProbe> probes, const SweepConfig& config,
                                   std::span<const SweepSetting> settings, const SweepProgress& progress) {
  std::vector<SweepResult> out;
  out.reserve(settings.size());
  for (std::size_t i = 0; i < settings.size(); ++i) {
    if (progress && !progress(i, settings.size(), setting_label(settings[i]))) throw BuildCancelled();
    const auto same = earlier_same_build(settings, i);
    out.push_back(measure_sweep_setting(triangles, rays, probes, config, settings[i], same ? &out[*same] : nullptr));
  }
  return out;
}

// ---- analysis ------------------------------------------------------------------------

std::vector<std::size_t> pareto_front(std::span<const ParetoPoint> points) {
  const auto finite = [](const ParetoPoint& p) {
    return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
  };
  std::vector<std::size_t> front;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const ParetoPoint& p = points[i];
    if (!finite(p)) continue;
    bool dominated = false;
    for (std::size_t j = 0; j < points.size() && !dominated; ++j) {
      const ParetoPoint& o = points[j];
      if (j == i || !finite(o)) continue;
      dominated = o.x <= p.x && o.y <= p.y && o.z <= p.z && (o.x < p.x || o.y < p.y || o.z < p.z);
    }
    if (!dominated) front.push_back(i);
  }
  std::sort(front.begin(), front.end(), [&](std::size_t a, std::size_t b) {
    return std::tie(points[a].x, points[a].y, a) < std::tie(points[b].x, points[b].y, b);
  });
  return front;
}

std::vector<ParetoPoint> sweep_points(std::span<const SweepResult> results, double rays) {
  std::vector<ParetoPoint> p;
  p.reserve(results.size());
  for (const SweepResult& r : results)
    p.push_back({r.build_ms, r.trace_ms(rays), r.edges.probes > 0 ? static_cast<double>(r.edges.misses) : 0.0});
  return p;
}

std::size_t best_for_budget(std::span<const SweepResult> results, double rays) {
  if (results.empty()) throw std::invalid_argument("best_for_budget: no results");
  std::size_t best = 0;
  for (std::size_t i = 1; i < results.size(); ++i)
    if (results[i].total_ms(rays) < results[best].total_ms(rays)) best = i;
  return best;
}

std::optional<std::size_t> best_without_leaks(std::span<const SweepResult> results, double rays) {
  std::optional<std::size_t> best;
  for (std::size_t i = 0; i < results.size(); ++i)
    if (results[i].edges.probes > 0 && results[i].edges.misses == 0 &&
        (!best || results[i].total_ms(rays) < results[*best].total_ms(rays)))
      best = i;
  return best;
}

TimingScatter timing_scatter(std::span<const SweepResult> results) {
  const auto spread = [](const std::vector<double>& runs) {
    if (runs.size() < 2) return 0.0;
    const auto [lo, hi] = std::minmax_element(runs.begin(), runs.end());
    return *lo > 0.0 ? (*hi - *lo) / *lo : 0.0;
  };
  TimingScatter t;
  for (const SweepResult& r : results) {
    t.rays_per_s = std::max(t.rays_per_s, spread(r.rays_per_s_runs));
    t.build_ms = std::max(t.build_ms, spread(r.build_ms_runs));
  }
  return t;
}

std::string sweep_csv(std::span<const SweepResult> results, double ray_budget) {
  std::ostringstream os;
  os.precision(10);
  std::vector<std::string> params;
  if (!results.empty())
    for (const auto& [k, v] : results.front().setting) params.push_back(k);
  for (const std::string& p : params) os << p << ',';
  os << "label,triangle_test,build_ms,memory_bytes,nodes,leaves,max_depth,sah_cost,epo,nodes_per_ray,"
        "prims_per_ray,hit_fraction,rays_per_s,ray_budget,trace_ms_budget,total_ms_budget,edge_probes,"
        "edge_misses,edge_double_hits,ray_double_hits,build_of\n";
  for (const SweepResult& r : results) {
    for (const auto& [k, v] : r.setting) os << v << ',';
    os << '"' << setting_label(r.setting) << "\"," << r.triangle_test << ',' << r.build_ms << ',' << r.memory_bytes
       << ',' << r.nodes << ',' << r.leaves << ',' << r.max_depth << ',';
    if (r.sah_cost > 0) os << r.sah_cost;  // empty: the structure reports none (grid, voxels)
    os << ',';
    if (r.epo >= 0) os << r.epo;
    os << ',' << r.nodes_per_ray << ',' << r.prims_per_ray << ',' << r.hit_fraction << ',' << r.rays_per_s << ','
       << ray_budget << ',' << r.trace_ms(ray_budget) << ',' << r.total_ms(ray_budget) << ',' << r.edges.probes << ','
       << r.edges.misses << ',' << r.edges.double_hits << ',' << r.ray_double_hits << ",\"" << r.build_of << "\"\n";
  }
  return os.str();
}

}  // namespace accelviz

namespace accelviz {

std::vector<Ray> sweep_ray_set(const Scene& scene, const Camera& camera, int width, int height, RayKind kind,
                               std::uint64_t seed, unsigned threads, bool* synthetic_light) {
  if (synthetic_light) *synthetic_light = false;
  std::vector<Ray> primary = primary_rays(camera, width, height);
  if (kind == RayKind::primary) return primary;
  BvhOptions opts;
  opts.compute_epo = false;
  opts.threads = threads;
  const Bvh bvh(scene.triangles, opts);
  std::vector<Hit> hits(primary.size());
  trace_closest(bvh, primary, hits, QueryOptions{}, resolve_threads(threads));
  if (kind == RayKind::diffuse) return diffuse_rays(scene.triangles, primary, hits, seed);
  if (synthetic_light) *synthetic_light = casting_lights(scene).empty();
  return shadow_rays(scene.triangles, primary, hits, shadow_lights(scene, true));
}

}  // namespace accelviz
