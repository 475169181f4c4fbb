#include "ui/app/app_config.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <deque>
#include <functional>
#include <limits>
#include <optional>

#include "core/analysis/sah.h"

namespace accelviz {
namespace {

// ---- text to values ---------------------------------------------------------

std::optional<long long> to_int(std::string_view s) {
  long long v = 0;
  const char* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, v);
  if (r.ec != std::errc() || r.ptr != end || s.empty()) return std::nullopt;
  return v;
}

std::optional<double> to_double(std::string_view s) {
  if (s.empty()) return std::nullopt;
  // from_chars for double is in GCC 12's libstdc++; it rejects "+1" and
  // leading blanks, which is what a strict settings reader wants.
  double v = 0.0;
  const char* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, v);
  if (r.ec != std::errc() || r.ptr != end || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::optional<bool> to_bool(std::string_view s) {
  if (s == "on" || s == "true" || s == "1" || s == "yes") return true;
  if (s == "off" || s == "false" || s == "0" || s == "no") return false;
  return std::nullopt;
}

std::string quoted(std::string_view v) {
  std::string q(1, '\'');
  q += v;
  q += '\'';
  return q;
}

const char* on_off(bool b) {
  return b ? "on" : "off";
}

// ---- the table ----------------------------------------------------------------

using Getter = std::function<std::string(const AppConfig&)>;
// Returns an error message without the key prefix, empty on success.
using Setter = std::function<std::string(AppConfig&, std::string_view)>;

struct Entry {
  OptionInfo info;
  Getter get;
  Setter set;
};

// OptionInfo holds views: texts made for the table live as long as it (built
// once, by entries()' static initialisation).
std::string_view kept(std::string text) {
  static std::deque<std::string> texts;
  return texts.emplace_back(std::move(text));
}

// An integer bound as the values texts write it: "256", "1000000", "2^31-1".
std::string int_bound_text(long long v) {
  return v == std::numeric_limits<int>::max() ? "2^31-1" : std::to_string(v);
}

// A float bound: "0", "0.5", "1000", "1e6".
std::string bound_text(double v) {
  if (v >= 1e4 && v == std::floor(v)) {
    const int e = static_cast<int>(std::lround(std::log10(v)));
    if (std::pow(10.0, e) == v) return "1e" + std::to_string(e);
  }
  return format_number(v);
}

// What an option accepts, from its bounds (so the help texts, the docs and
// the errors cannot drift from the check).
std::string range_text(double lo, double hi, bool lo_open) {
  return lo_open ? "> " + bound_text(lo) + ", at most " + bound_text(hi) : bound_text(lo) + ".." + bound_text(hi);
}

Entry int_option(std::string_view key, std::string_view help, long long lo, long long hi,
                 std::function<int&(AppConfig&)> field) {
  const std::string_view values = kept(int_bound_text(lo) + ".." + int_bound_text(hi));
  return {{key, values, help},
          [field](const AppConfig& c) { return std::to_string(field(const_cast<AppConfig&>(c))); },
          [field, lo, hi, values](AppConfig& c, std::string_view v) -> std::string {
            const auto x = to_int(v);
            if (!x || *x < lo || *x > hi) return "expected an integer in " + std::string(values) + ", got " + quoted(v);
            field(c) = static_cast<int>(*x);
            return {};
          }};
}

// `lo_open`: the lower bound itself is refused (costs must be > 0).
Entry float_option(std::string_view key, std::string_view help, double lo, double hi, bool lo_open,
                   std::function<float&(AppConfig&)> field) {
  const std::string_view values = kept(range_text(lo, hi, lo_open));
  return {{key, values, help},
          [field](const AppConfig& c) { return format_number(field(const_cast<AppConfig&>(c))); },
          [field, lo, hi, lo_open, values](AppConfig& c, std::string_view v) -> std::string {
            const auto x = to_double(v);
            if (!x || *x > hi || *x < lo || (lo_open && *x == lo))
              return "expected a number " + std::string(values) + ", got " + quoted(v);
            field(c) = static_cast<float>(*x);
            return {};
          }};
}

Entry bool_option(std::string_view key, std::string_view help, std::function<bool&(AppConfig&)> field) {
  return {{key, "on|off", help},
          [field](const AppConfig& c) { return std::string(on_off(field(const_cast<AppConfig&>(c)))); },
          [field](AppConfig& c, std::string_view v) -> std::string {
            const auto b = to_bool(v);
            if (!b) return "expected on or off, got " + quoted(v);
            field(c) = *b;
            return {};
          }};
}

// An option with a fixed set of names; what it accepts ("a|b|c", for the
// help texts and the error) is those names, so the two cannot drift apart.
template <typename T>
Entry enum_option(std::string_view key, std::string_view help, std::vector<std::pair<std::string_view, T>> names,
                  std::function<T&(AppConfig&)> field) {
  std::string j;
  for (const auto& [n, t] : names) {
    if (!j.empty()) j += '|';
    j += n;
  }
  const std::string_view values = kept(std::move(j));
  return {{key, values, help},
          [field, names](const AppConfig& c) {
            const T v = field(const_cast<AppConfig&>(c));
            for (const auto& [n, t] : names)
              if (t == v) return std::string(n);
            return std::string();
          },
          [field, names, values](AppConfig& c, std::string_view v) -> std::string {
            for (const auto& [n, t] : names)
              if (n == v) {
                field(c) = t;
                return {};
              }
            return "expected one of " + std::string(values) + ", got " + quoted(v);
          }};
}

const std::vector<Entry>& entries() {
  static const std::vector<Entry> table = [] {
    std::vector<Entry> t;
    // Structure type.
    std::string joined;
    for (const std::string& n : structure_names()) joined += (joined.empty() ? "" : "|") + n;
    const std::string_view values = kept(std::move(joined));
    t.push_back({{"structure", values, "structure to build"},
                 [](const AppConfig& c) { return c.structure.name; },
                 [values](AppConfig& c, std::string_view v) -> std::string {
                   const auto& names = structure_names();
                   if (std::find(names.begin(), names.end(), v) == names.end())
                     return "expected one of " + std::string(values) + ", got " + quoted(v);
                   c.structure.name = std::string(v);
                   return {};
                 }});
    // BVH (BvhOptions, core/accel/bvh/bvh.h).
    t.push_back(
        enum_option<BvhSplitter>("splitter", "BVH split: binned SAH (Wald 2007), exact SAH sweep, median, LBVH",
                                 {{"binned", BvhSplitter::binned_sah},
                                  {"exact", BvhSplitter::exact_sah},
                                  {"median", BvhSplitter::median},
                                  {"lbvh", BvhSplitter::lbvh}},
                                 [](AppConfig& c) -> BvhSplitter& { return c.structure.options.bvh.splitter; }));
    t.push_back(int_option("buckets", "BVH binned SAH buckets", 2, 256,
                           [](AppConfig& c) -> int& { return c.structure.options.bvh.buckets; }));
    // Raising the cap along with the leaf size keeps the pair valid, as the
    // command line's --leaf does.
    t.push_back({{"leaf", "1..255", "BVH: nodes with at most this many triangles are always leaves"},
                 [](const AppConfig& c) { return std::to_string(c.structure.options.bvh.max_leaf_size); },
                 [](AppConfig& c, std::string_view v) -> std::string {
                   const auto x = to_int(v);
                   if (!x || *x < 1 || *x > 255) return "expected an integer in 1..255, got " + quoted(v);
                   BvhOptions& b = c.structure.options.bvh;
                   b.max_leaf_size = static_cast<int>(*x);
                   b.leaf_size_cap = std::max(b.leaf_size_cap, b.max_leaf_size);
                   return {};
                 }});
    t.push_back({{"leaf-cap", "leaf..255", "BVH: largest leaf the SAH may keep"},
                 [](const AppConfig& c) { return std::to_string(c.structure.options.bvh.leaf_size_cap); },
                 [](AppConfig& c, std::string_view v) -> std::string {
                   BvhOptions& b = c.structure.options.bvh;
                   const auto x = to_int(v);
                   if (!x || *x < b.max_leaf_size || *x > 255)
                     return "expected an integer in " + std::to_string(b.max_leaf_size) +
                            "..255 (at least leaf), got " + quoted(v);
                   b.leaf_size_cap = static_cast<int>(*x);
                   return {};
                 }});
    t.push_back(float_option("ctrav", "BVH SAH cost of an inner-node visit (C_trav; also the cost metric's)",
                             kMinCostConstant, kMaxCostConstant, false,
                             [](AppConfig& c) -> float& { return c.structure.options.bvh.cost_traversal; }));
    t.push_back(float_option("cisect", "BVH SAH cost of a triangle test (C_isect; also the cost metric's)",
                             kMinCostConstant, kMaxCostConstant, false,
                             [](AppConfig& c) -> float& { return c.structure.options.bvh.cost_intersect; }));
    t.push_back(int_option("threads", "build threads (0: all hardware threads)", 0, 256, [](AppConfig& c) -> int& {
      // unsigned in StructureOptions; the range keeps the cast exact.
      return reinterpret_cast<int&>(c.structure.options.threads);
    }));
    t.push_back(bool_option("epo", "BVH: compute the EPO figure after the build",
                            [](AppConfig& c) -> bool& { return c.structure.options.bvh.compute_epo; }));
    // K-D tree (KdTreeOptions).
    t.push_back(float_option("kd-ctrav", "K-D tree C_trav", kMinCostConstant, kMaxCostConstant, false,
                             [](AppConfig& c) -> float& { return c.structure.options.kdtree.cost_traversal; }));
    t.push_back(float_option("kd-cisect", "K-D tree C_isect", kMinCostConstant, kMaxCostConstant, false,
                             [](AppConfig& c) -> float& { return c.structure.options.kdtree.cost_intersect; }));
    t.push_back(int_option("kd-max-depth", "K-D tree deepest leaf (0: auto, 8 + 1.3 log2 N)", 0, 64,
                           [](AppConfig& c) -> int& { return c.structure.options.kdtree.max_depth; }));
    t.push_back(int_option("kd-leaf", "K-D tree: nodes with at most this many triangles are leaves", 1, 1000000,
                           [](AppConfig& c) -> int& { return c.structure.options.kdtree.max_leaf_size; }));
    t.push_back(float_option("kd-empty-bonus", "K-D tree SAH discount for a split with an empty side", 0, 1, false,
                             [](AppConfig& c) -> float& { return c.structure.options.kdtree.empty_bonus; }));
    t.push_back(bool_option("kd-perfect-splits", "K-D tree: clip triangles to the node box (Havran 2000)",
                            [](AppConfig& c) -> bool& { return c.structure.options.kdtree.perfect_splits; }));
    t.push_back(bool_option("kd-mailboxing", "K-D tree: skip triangles this ray already tested",
                            [](AppConfig& c) -> bool& { return c.structure.options.kdtree.mailboxing; }));
    // Uniform grid (GridOptions).
    t.push_back({{"grid-res", "X,Y,Z, each 0..4096 (0,0,0: auto; zeros only all together)", "grid cells per axis"},
                 [](const AppConfig& c) {
                   const auto& r = c.structure.options.grid.resolution;
                   return std::to_string(r[0]) + "," + std::to_string(r[1]) + "," + std::to_string(r[2]);
                 },
                 [](AppConfig& c, std::string_view v) -> std::string {
                   std::array<int, 3> r{};
                   std::string_view rest = v;
                   for (int a = 0; a < 3; ++a) {
                     const auto comma = rest.find(',');
                     const std::string_view part = a < 2 ? rest.substr(0, comma) : rest;
                     const auto x = to_int(part);
                     if ((a < 2 && comma == std::string_view::npos) || !x || *x < 0 || *x > 4096)
                       return "expected X,Y,Z with each 0..4096 (0,0,0: auto), got " + quoted(v);
                     r[a] = static_cast<int>(*x);
                     if (a < 2) rest = rest.substr(comma + 1);
                   }
                   const bool all_zero = r[0] == 0 && r[1] == 0 && r[2] == 0;
                   const bool all_set = r[0] > 0 && r[1] > 0 && r[2] > 0;
                   if (!all_zero && !all_set) return "expected 0,0,0 (auto) or three sizes >= 1, got " + quoted(v);
                   c.structure.options.grid.resolution = r;
                   return {};
                 }});
    t.push_back(float_option("grid-lambda", "grid: automatic resolution gives about lambda*N cells", 0, 1e4, true,
                             [](AppConfig& c) -> float& { return c.structure.options.grid.lambda; }));
    t.push_back(bool_option("grid-exact", "grid: reference triangles only in the cells they overlap",
                            [](AppConfig& c) -> bool& { return c.structure.options.grid.exact_overlap; }));
    t.push_back(bool_option("grid-mailboxing", "grid: skip triangles this ray already tested",
                            [](AppConfig& c) -> bool& { return c.structure.options.grid.mailboxing; }));
    // Octree (OctreeOptions).
    t.push_back(int_option("octree-depth", "octree deepest cell", 0, kOctreeMaxDepth,
                           [](AppConfig& c) -> int& { return c.structure.options.octree.max_depth; }));
    t.push_back(int_option("octree-leaf", "octree: cells with more triangles are split", 1, 1000000,
                           [](AppConfig& c) -> int& { return c.structure.options.octree.max_leaf_size; }));
    t.push_back(bool_option("octree-mailboxing", "octree: skip triangles this ray already tested",
                            [](AppConfig& c) -> bool& { return c.structure.options.octree.mailboxing; }));
    t.push_back(bool_option("octree-cost-termination", "octree: stop splitting where the SAH rates it no cheaper",
                            [](AppConfig& c) -> bool& { return c.structure.options.octree.cost_termination; }));
    // Voxels (VoxelOptions).
    t.push_back(int_option("voxel-level", "voxels per axis = 2^level", 0, kVoxelMaxLevel,
                           [](AppConfig& c) -> int& { return c.structure.options.voxels.level; }));
    // Embree (EmbreeOptions).
    t.push_back(enum_option<EmbreeQuality>(
        "embree-quality", "Embree build quality",
        {{"low", EmbreeQuality::low}, {"medium", EmbreeQuality::medium}, {"high", EmbreeQuality::high}},
        [](AppConfig& c) -> EmbreeQuality& { return c.structure.options.embree.quality; }));
    t.push_back(bool_option("embree-robust", "Embree: robust mode (no optimisations that lose watertightness)",
                            [](AppConfig& c) -> bool& { return c.structure.options.embree.robust; }));
    std::vector<std::pair<std::string_view, EmbreeIsa>> isa_names;  // embree_isa_name's
    for (EmbreeIsa isa : kEmbreeIsas) isa_names.emplace_back(embree_isa_name(isa), isa);
    t.push_back(enum_option<EmbreeIsa>(
        "embree-isa", "Embree: the kernels it may use (auto: the widest the CPU has; avx2: our fast path's)",
        std::move(isa_names), [](AppConfig& c) -> EmbreeIsa& { return c.structure.options.embree.isa; }));
    // Query choices.
    t.push_back(
        enum_option<TriangleTest>("triangle-test", "ray-triangle test: Woop 2013 watertight or Moller-Trumbore",
                                  {{"watertight", TriangleTest::watertight}, {"fast", TriangleTest::moller_trumbore}},
                                  [](AppConfig& c) -> TriangleTest& { return c.structure.query.triangle_test; }));
    t.push_back(bool_option("ordered", "front-to-back child order (off: fixed order)",
                            [](AppConfig& c) -> bool& { return c.structure.query.ordered; }));
    t.push_back(bool_option("back-to-front", "BVH, ordered: the farther child first (the worst order; same hit)",
                            [](AppConfig& c) -> bool& { return c.structure.query.back_to_front; }));
    t.push_back(bool_option("xray", "BVH: count the full traversal as if no hit ended it (same hit)",
                            [](AppConfig& c) -> bool& { return c.structure.query.xray; }));
    // View layers.
    t.push_back(bool_option("mesh", "shaded mesh", [](AppConfig& c) -> bool& { return c.view.show_mesh; }));
    t.push_back(
        bool_option("wireframe", "triangle edges", [](AppConfig& c) -> bool& { return c.view.show_wireframe; }));
    t.push_back(bool_option("boxes", "node boxes", [](AppConfig& c) -> bool& { return c.view.show_boxes; }));
    t.push_back(enum_option<BoxMode>("box-mode", "which node boxes: one depth, a depth range, leaves, a subtree",
                                     {{"depth", BoxMode::depth},
                                      {"range", BoxMode::depth_range},
                                      {"leaves", BoxMode::leaves},
                                      {"subtree", BoxMode::subtree}},
                                     [](AppConfig& c) -> BoxMode& { return c.view.box_mode; }));
    t.push_back(int_option("box-depth", "depth of the boxes (range: first depth)", 0, 64,
                           [](AppConfig& c) -> int& { return c.view.box_depth; }));
    t.push_back(int_option("box-depth-last", "range: last depth (inclusive)", 0, 64,
                           [](AppConfig& c) -> int& { return c.view.box_depth_last; }));
    t.push_back(int_option("box-node", "subtree: the selected node", 0, std::numeric_limits<int>::max(),
                           [](AppConfig& c) -> int& { return c.view.box_node; }));
    t.push_back(enum_option<BoxColorBy>("box-color", "box colours: by depth or by share of the SAH cost",
                                        {{"depth", BoxColorBy::depth}, {"sah", BoxColorBy::sah_share}},
                                        [](AppConfig& c) -> BoxColorBy& { return c.view.box_color; }));
    t.push_back(bool_option("boxes-through-mesh", "boxes are not hidden by the mesh",
                            [](AppConfig& c) -> bool& { return c.view.boxes_through_mesh; }));
    t.push_back(enum_option<BoxLevel>("box-level",
                                      "two-level: top-level node boxes, or every instance's BLAS boxes in world space",
                                      {{"tlas", BoxLevel::tlas}, {"blas", BoxLevel::blas}},
                                      [](AppConfig& c) -> BoxLevel& { return c.view.box_level; }));
    t.push_back(int_option("box-instance", "two-level, blas level: only this instance's boxes (-1: all)", -1,
                           std::numeric_limits<int>::max(), [](AppConfig& c) -> int& { return c.view.box_instance; }));
    t.push_back(bool_option("instance-colors", "two-level: each instance in its own colour (hashed from its id)",
                            [](AppConfig& c) -> bool& { return c.view.instance_colors; }));
    t.push_back(enum_option<HeatmapDisplay>(
        "heatmap", "per-pixel metric: off, replacing the mesh, or blended over it",
        {{"off", HeatmapDisplay::off}, {"full", HeatmapDisplay::full_screen}, {"blend", HeatmapDisplay::blend}},
        [](AppConfig& c) -> HeatmapDisplay& { return c.view.heatmap; }));
    t.push_back(enum_option<HeatMetric>("metric", "heatmap metric",
                                        {{"nodes", HeatMetric::nodes},
                                         {"prims", HeatMetric::prims},
                                         {"cost", HeatMetric::cost},
                                         {"shaded", HeatMetric::shaded},
                                         {"depth", HeatMetric::depth},
                                         {"instances", HeatMetric::instances}},
                                        [](AppConfig& c) -> HeatMetric& { return c.view.metric; }));
    t.push_back(bool_option("heatmap-gpu",
                            "trace the heatmap on the GPU (compute shader, BVH only; otherwise on the CPU)",
                            [](AppConfig& c) -> bool& { return c.view.heatmap_gpu; }));
    t.push_back(float_option("heatmap-gpu-ms",
                             "GPU heatmap: ms of tracing per frame, in row bands (0: one 8-row band a frame)", 0, 1000,
                             false, [](AppConfig& c) -> float& { return c.view.heatmap_gpu_ms; }));
    t.push_back(enum_option<ColorMap>(
        "colormap", "heatmap colour map",
        {{"viridis", ColorMap::viridis}, {"inferno", ColorMap::inferno}, {"turbo", ColorMap::turbo}},
        [](AppConfig& c) -> ColorMap& { return c.view.colormap; }));
    t.push_back(float_option("opacity", "blend: heatmap opacity", 0, 1, false,
                             [](AppConfig& c) -> float& { return c.view.opacity; }));
    t.push_back({{"scale", "auto|MIN,MAX", "heatmap range: the image's [0, max] or locked"},
                 [](const AppConfig& c) {
                   return c.view.auto_scale ? std::string("auto")
                                            : format_number(c.view.scale_min) + "," + format_number(c.view.scale_max);
                 },
                 [](AppConfig& c, std::string_view v) -> std::string {
                   if (v == "auto") {
                     c.view.auto_scale = true;
                     return {};
                   }
                   const auto comma = v.find(',');
                   const auto lo = comma == std::string_view::npos ? std::nullopt : to_double(v.substr(0, comma));
                   const auto hi = comma == std::string_view::npos ? std::nullopt : to_double(v.substr(comma + 1));
                   if (!lo || !hi || !(*hi > *lo)) return "expected auto or MIN,MAX with MIN < MAX, got " + quoted(v);
                   c.view.auto_scale = false;
                   c.view.scale_min = static_cast<float>(*lo);
                   c.view.scale_max = static_cast<float>(*hi);
                   return {};
                 }});
    t.push_back(bool_option("legend", "heatmap legend", [](AppConfig& c) -> bool& { return c.view.show_legend; }));
    t.push_back(bool_option("ray-path", "the inspected ray: path, visited boxes, tested triangles",
                            [](AppConfig& c) -> bool& { return c.view.show_ray_path; }));
    t.push_back({{"msaa", "1|2|4|8", "multisampling of the 3D view"},
                 [](const AppConfig& c) { return std::to_string(c.view.msaa); },
                 [](AppConfig& c, std::string_view v) -> std::string {
                   const auto x = to_int(v);
                   if (!x || (*x != 1 && *x != 2 && *x != 4 && *x != 8))
                     return "expected 1, 2, 4 or 8, got " + quoted(v);
                   c.view.msaa = static_cast<int>(*x);
                   return {};
                 }});
    return t;
  }();
  return table;
}

const Entry* find_entry(std::string_view key) {
  for (const Entry& e : entries())
    if (e.info.key == key) return &e;
  return nullptr;
}

}  // namespace

std::string format_number(double v) {
  // Options are floats: the shortest text that reads back to the same
  // float, fixed or scientific, whichever is shorter ("40", "0.25", "1e-07").
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, static_cast<float>(v));
  return std::string(buf, r.ptr);
}

const std::vector<OptionInfo>& option_table() {
  static const std::vector<OptionInfo> infos = [] {
    std::vector<OptionInfo> v;
    for (const Entry& e : entries()) v.push_back(e.info);
    return v;
  }();
  return infos;
}

std::string apply_option(AppConfig& config, std::string_view key, std::string_view value) {
  const Entry* e = find_entry(key);
  if (!e) return "unknown option " + quoted(key) + " (see docs/gui.md for the list)";
  AppConfig copy = config;  // all or nothing
  const std::string error = e->set(copy, value);
  if (!error.empty()) return std::string(key) + ": " + error;
  config = copy;
  return {};
}

std::string option_value(const AppConfig& config, std::string_view key) {
  const Entry* e = find_entry(key);
  return e ? e->get(config) : std::string();
}

std::vector<std::pair<std::string, std::string>> option_values(const AppConfig& config) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const Entry& e : entries()) out.emplace_back(std::string(e.info.key), e.get(config));
  return out;
}

std::vector<std::string_view> structure_option_keys(std::string_view name) {
  // tlas builds its BLASes and its TLAS with the BVH's options (core/accel/factory.cpp).
  if (name == "bvh" || name == "tlas") return {"splitter", "buckets", "leaf", "leaf-cap", "ctrav", "cisect"};
  if (name == "kdtree")
    return {"kd-ctrav", "kd-cisect", "kd-max-depth", "kd-leaf", "kd-empty-bonus", "kd-perfect-splits", "kd-mailboxing"};
  if (name == "grid") return {"grid-res", "grid-lambda", "grid-exact", "grid-mailboxing"};
  if (name == "octree") return {"octree-depth", "octree-leaf", "octree-mailboxing", "octree-cost-termination"};
  if (name == "voxels") return {"voxel-level"};
  if (name == "embree") return {"embree-quality", "embree-robust", "embree-isa"};
  return {};
}

bool same_build(const StructureChoice& a, const StructureChoice& b) {
  if (a.name != b.name) return false;
  AppConfig ca, cb;
  ca.structure = a;
  cb.structure = b;
  for (std::string_view key : structure_option_keys(a.name))
    if (option_value(ca, key) != option_value(cb, key)) return false;
  // The thread count and EPO change what a build reports, so they count too.
  return option_value(ca, "threads") == option_value(cb, "threads") &&
         (a.name != "bvh" || option_value(ca, "epo") == option_value(cb, "epo"));
}

std::string describe_structure(const StructureChoice& choice) {
  AppConfig c;
  c.structure = choice;
  std::string s = choice.name;
  const auto keys = structure_option_keys(choice.name);
  if (!keys.empty()) {
    s += " (";
    for (std::size_t i = 0; i < keys.size(); ++i)
      s += (i ? ", " : "") + std::string(keys[i]) + "=" + option_value(c, keys[i]);
    s += ")";
  }
  return s;
}

HeatmapOptions view_heatmap_options(const AppConfig& config, int width, int height) {
  const StructureOptions& so = config.structure.options;
  return {.metric = config.view.metric,
          .width = width,
          .height = height,
          .threads = so.threads,
          .query = config.structure.query,
          .c_trav = so.bvh.cost_traversal,
          .c_isect = so.bvh.cost_intersect};
}

std::string screenshot_caption(const AppConfig& config) {
  std::string s = describe_structure(config.structure);
  s += ", " + option_value(config, "triangle-test");
  if (!config.structure.query.ordered)
    s += ", unordered";
  else if (config.structure.query.back_to_front)
    s += ", back-to-front";
  if (config.structure.query.xray) s += ", x-ray";
  if (config.view.heatmap != HeatmapDisplay::off) {
    s += ", heatmap " + std::string(metric_name(config.view.metric));
    // In the structure's words where they differ, as the legend says (a grid's nodes are cells).
    const std::string word = metric_short_label(config.view.metric, config.structure.name);
    if (config.view.metric == HeatMetric::nodes && word != metric_short_label(config.view.metric))
      s += " (" + word + ")";
    if (config.view.metric != HeatMetric::shaded)  // grey shading: no colour map, no scale
      s += " " + std::string(colormap_name(config.view.colormap)) + " scale " + option_value(config, "scale");
    if (config.view.heatmap == HeatmapDisplay::blend) s += " blend " + option_value(config, "opacity");
  }
  return s;
}

}  // namespace accelviz
