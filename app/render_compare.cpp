#include "app/render_compare.h"

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <limits>
#include <set>
#include <sstream>

#include "core/analysis/caption.h"
#include "core/analysis/heatmap.h"
#include "core/analysis/insight/compare_images.h"
#include "core/analysis/sah.h"
#include "core/query/batch.h"
#include "core/query/camera.h"
#include "core/query/ray_sets.h"
#include "core/scene/load.h"
#include "core/util/json_text.h"

namespace accelviz::cli {

namespace {

template <typename T>
T parse_number(const std::string& key, const std::string& value) {
  try {
    std::size_t used = 0;
    T v;
    if constexpr (std::is_same_v<T, int>)
      v = std::stoi(value, &used);
    else
      v = std::stod(value, &used);
    if (used != value.size()) throw std::invalid_argument("trailing");
    return v;
  } catch (const std::out_of_range&) {
    throw UsageError("--compare: " + key + "=" + value + ": out of range");
  } catch (const std::logic_error&) {
    throw UsageError("--compare: " + key + "=" + value + ": not a number");
  }
}

void require_one_of(const std::string& key, const std::string& value, std::initializer_list<const char*> allowed) {
  std::string list;
  for (const char* a : allowed) {
    if (value == a) return;
    list += (list.empty() ? "" : ", ") + std::string(a);
  }
  throw UsageError("--compare: " + key + "=" + value + ": expected one of " + list);
}

}  // namespace

CompareSide parse_compare_spec(const std::string& spec, const CompareSide& a) {
  CompareSide b = a;
  std::string text = spec;
  for (char& ch : text)
    if (ch == ',') ch = ' ';
  std::istringstream in(text);
  std::string pair;
  int pairs = 0;
  std::set<std::string> keys;
  while (in >> pair) {
    ++pairs;
    const auto eq = pair.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == pair.size())
      throw UsageError("--compare: '" + pair + "': expected key=value");
    const std::string key = pair.substr(0, eq), value = pair.substr(eq + 1);
    if (!keys.insert(key).second) throw UsageError("--compare: " + key + " given twice in '" + spec + "'");
    if (key == "structure") {
      bool known = false;
      for (const std::string& n : structure_names()) known = known || n == value;
      if (!known) throw UsageError("--compare: structure=" + value + ": unknown structure");
      b.structure = value;
    } else if (key == "splitter") {
      require_one_of(key, value, {"binned", "exact", "median", "lbvh"});
      b.structure_opts.splitter = value;
    } else if (key == "buckets") {
      const int v = parse_number<int>(key, value);
      if (v < 2 || v > 256) throw UsageError("--compare: buckets=" + value + ": expected 2..256");
      b.structure_opts.buckets = v;
    } else if (key == "leaf" || key == "leaf-cap") {
      const int v = parse_number<int>(key, value);
      if (v < 1 || v > 255) throw UsageError("--compare: " + key + "=" + value + ": expected 1..255");
      (key == "leaf" ? b.structure_opts.leaf : b.structure_opts.leaf_cap) = v;
      if (key == "leaf-cap") b.structure_opts.leaf_cap_given = true;
    } else if (key == "ctrav" || key == "cisect") {
      const double v = parse_number<double>(key, value);
      if (const std::string problem = cost_constant_problem(v); !problem.empty())
        throw UsageError("--compare: " + key + "=" + value + ": " + problem + " (as --" + key + ")");
      (key == "ctrav" ? b.structure_opts.ctrav : b.structure_opts.cisect) = static_cast<float>(v);
    } else if (key == "embree-quality") {
      require_one_of(key, value, {"low", "medium", "high"});
      b.structure_opts.embree_quality = value;
    } else if (key == "triangle-test") {
      require_one_of(key, value, {"watertight", "fast"});
      b.triangle_test = value;
    } else if (key == "order") {
      require_one_of(key, value, {"front-to-back", "back-to-front", "unordered"});
      b.order = value;
    } else if (key == "xray") {
      require_one_of(key, value, {"0", "1"});
      b.xray = value == "1";
    } else {
      throw UsageError("--compare: unknown key '" + key +
                       "' (structure, splitter, buckets, leaf, leaf-cap, ctrav, cisect, embree-quality, "
                       "triangle-test, order, xray)");
    }
  }
  if (pairs == 0) throw UsageError("--compare: empty; give B's differences as key=value pairs");
  return b;
}

ComparePaths compare_paths(const std::string& out) {
  const std::filesystem::path p(out);
  const std::filesystem::path dir = p.parent_path();
  const std::string stem = p.stem().string(), ext = p.extension().string();  // .png (run_render checked)
  const auto make = [&](const char* suffix) { return (dir / (stem + suffix + ext)).string(); };
  return {make("-a"), make("-b"), make("-diff")};
}

std::string order_problem(const CompareSide& side) {
  const std::string& st = side.structure;
  const bool every_order = st == "bvh" || st == "tlas";
  const bool unordered_too = st == "kdtree" || st == "octree";
  if (side.xray && !every_order)
    return "--xray: bvh and tlas only (" + st + " counts the walk that the closest hit ends)";
  if (side.order == "back-to-front" && !every_order)
    return "--order back-to-front: bvh and tlas only (" + st +
           (unordered_too ? ": front-to-back or unordered)" : " has no child order)");
  if (side.order == "unordered" && !every_order && !unordered_too)
    return "--order unordered: " + st + " has no child order (bvh, tlas, kdtree and octree have)";
  return {};
}

QueryOptions query_of(const CompareSide& side) {
  QueryOptions q;
  q.triangle_test = parse_triangle_test(side.triangle_test);
  q.ordered = side.order != "unordered";
  q.back_to_front = side.order == "back-to-front";
  q.xray = side.xray;
  return q;
}

nlohmann::json describe_side(const CompareSide& side, HeatMetric metric) {
  const std::string& st = side.structure;
  const bool bvh_options = st == "bvh" || st == "tlas";  // tlas: both levels use the BVH's options
  nlohmann::json d = {{"structure", st}};
  if (st != "embree" && st != "voxels") d["triangle_test"] = side.triangle_test;  // Embree: its own test
  if (bvh_options) {
    d["splitter"] = side.structure_opts.splitter;
    if (side.structure_opts.splitter == "binned") d["buckets"] = side.structure_opts.buckets;
    d["leaf"] = side.structure_opts.leaf;
    d["leaf_cap"] = std::max(side.structure_opts.leaf, side.structure_opts.leaf_cap);  // as built
  }
  // The SAH's costs, and the cost metric's weights whatever the structure.
  if (bvh_options || metric == HeatMetric::cost) {
    d["ctrav"] = side.structure_opts.ctrav;
    d["cisect"] = side.structure_opts.cisect;
  }
  if (bvh_options || st == "kdtree" || st == "octree") d["order"] = side.order;  // child order of their traversal
  if (bvh_options) d["xray"] = side.xray;
  if (st == "embree") {
    d["embree_quality"] = side.structure_opts.embree_quality;
    d["embree_robust"] = side.structure_opts.embree_robust;
  }
  return d;
}

HeatmapOptions heatmap_options_of(const CompareSide& side, HeatMetric metric, const ImageSize& size, unsigned threads) {
  return {.metric = metric,
          .width = size.width,
          .height = size.height,
          .threads = threads,
          .query = query_of(side),
          .c_trav = side.structure_opts.ctrav,
          .c_isect = side.structure_opts.cisect};
}

int run_render_compare(const CompareJob& job, const GlobalOptions& global) {
  const ComparePaths paths = compare_paths(job.out);
  for (const std::string* p : {&paths.a, &paths.b, &paths.diff}) check_output_path(*p, job.force);
  const ImageSize size = parse_size(job.size);
  const HeatMetric metric = parse_metric(job.metric).value();
  if (!metric_needs_stats(metric))
    throw UsageError("--compare: needs a cost metric (nodes, prims, cost or instances), not --metric " + job.metric);
  Progress progress(global.quiet);
  const Scene scene = load_scene_with_progress(job.scene, global.quiet, progress);
  const Camera camera = camera_for(job.camera, scene, size);

  nlohmann::json sides = nlohmann::json::object();
  MetricImage images[2];
  const CompareSide* side[2] = {&job.a, &job.b};
  // What a choice costs in time and what it changes: each side's closest hits of the view's primary rays,
  // timed without counters (the fast path), then the pixels whose hit differs.
  const std::vector<Ray> primary = primary_rays(camera, size.width, size.height);
  std::vector<Hit> hits[2];
  for (int s = 0; s < 2; ++s) {
    const CompareSide& c = *side[s];
    const char* tag = s == 0 ? "A" : "B";
    const std::unique_ptr<Accelerator> accel =
        build_with_progress(c.structure, scene, c.structure_opts.to_options(job.threads, /*compute_epo=*/false),
                            progress, std::string(tag) + ": " + c.structure);
    HeatmapOptions ho = heatmap_options_of(c, metric, size, job.threads);
    progress.begin(std::string("rendering ") + tag);
    ho.progress = progress.callback();
    HeatmapFigures fig;
    images[s] = render_metric(*accel, camera, ho, &fig);
    progress.end(std::to_string(static_cast<long long>(fig.render_ms)) + " ms");
    double total = 0.0;
    for (const float v : images[s].values)
      if (std::isfinite(v)) total += v;
    if (!accel->inspectable() && !global.quiet)
      std::cerr << "accelviz: " << tag << ": embree keeps no per-ray counters: its " << job.metric
                << " image is all 0\n";
    nlohmann::json d = describe_side(c, metric);
    d["build_ms"] = accel->build_stats().build_ms;
    d["per_ray_counters"] = accel->inspectable();  // Embree keeps none: its counter images are all 0
    d["sah_cost"] = accel->build_stats().sah_cost > 0.0 ? nlohmann::json(accel->build_stats().sah_cost)
                                                        : nlohmann::json(nullptr);  // none (embree, grid, voxels)
    d["mean"] = fig.mean;
    d["max"] = fig.max;
    d["total"] = total;
    progress.begin(std::string("timing ") + tag + "'s closest hits");
    TimedClosestHits timed =
        time_closest_hits(*accel, primary, query_of(c), resolve_threads(job.threads), 3, progress.callback());
    progress.end(std::to_string(static_cast<long long>(std::lround(timed.trace_ms))) + " ms");
    d["trace_ms"] = timed.trace_ms;
    d["hits"] = timed.hit_count;
    hits[s] = std::move(timed.hits);
    sides[s == 0 ? "a" : "b"] = d;
  }
  ABFigures ab;
  const MetricImage diff = difference_image(images[0], images[1], &ab);
  const MetricImage* both[] = {&images[0], &images[1]};
  const float locked = job.max_percentile > 0.0
                           ? heatmap_scale_max(ValueRange{0.0f, metric_percentile(both, job.max_percentile)}, 0.0f)
                           : locked_scale_max(images[0], images[1], job.max);
  ColorizeOptions co;
  co.map = parse_colormap(job.colormap).value();
  co.max = locked;
  co.legend = parse_legend_placement(job.legend).value();
  // A side without counters (Embree): its image is all 0 and no difference compares; the images say so.
  ColorizeOptions side_co[2] = {co, co};  // which side each image is, on one shared scale
  side_co[0].title_prefix = "A: ";
  side_co[0].scale_note = "scale shared with B";
  side_co[1].title_prefix = "B: ";
  side_co[1].scale_note = "scale shared with A";
  for (int s = 0; s < 2; ++s) side_co[s].structure = side[s]->structure;
  RgbImage rgb[2] = {colorize(images[0], side_co[0]), colorize(images[1], side_co[1])};
  std::string uncounted;
  for (int s = 0; s < 2; ++s)
    if (!sides[s == 0 ? "a" : "b"]["per_ray_counters"].get<bool>()) {
      uncounted = side[s]->structure;
      draw_note(rgb[s], "n/a: " + uncounted + " counts nothing per ray");
    }
  MetricImage shown_diff = diff;
  if (!uncounted.empty())  // no value anywhere: the background, not "B cheaper everywhere"
    std::fill(shown_diff.values.begin(), shown_diff.values.end(), std::numeric_limits<float>::quiet_NaN());
  RgbImage rgb_diff = colorize_difference(shown_diff, 0.0f, co.legend);
  if (!uncounted.empty())
    draw_note(rgb_diff, "n/a: " + uncounted + " counts nothing per ray, so no difference compares");
  // Captions: which side, its structure and the options the two differ in, the scene and the metric (the
  // images said only "A: cost" and "B: cost", not buckets=32 against 4).
  std::string caption_a, caption_b, caption_diff;
  {
    const nlohmann::json da = describe_side(*side[0], metric), db = describe_side(*side[1], metric);
    // A value as the caption writes it: a string without JSON's quotes.
    const auto text = [](const nlohmann::json& v) { return v.is_string() ? v.get<std::string>() : json_text(v); };
    std::string differs;
    for (const auto& [key, value] : da.items())
      if (key != "structure" && db.contains(key) && db[key] != value)
        differs += (differs.empty() ? "" : ", ") + key + " " + text(value) + " -> " + text(db[key]);
    const auto caption = [&](const nlohmann::json& d, const char* name) {
      std::string c = std::string(name) + ": " + text(d["structure"]);
      for (const auto& [key, value] : d.items())
        if (key != "structure" && (!da.contains(key) || !db.contains(key) || da[key] != db[key]))
          c += " " + key + "=" + text(value);
      return c + "; " + job.scene + ", " + job.metric + ", " + job.size;
    };
    caption_a = caption(da, "A");
    caption_b = caption(db, "B");
    caption_diff = "B - A (" + (differs.empty() ? std::string("no option differs") : differs) + "); " + job.scene +
                   ", " + job.metric + ", " + job.size;
    rgb[0] = add_caption(rgb[0], caption_a);
    rgb[1] = add_caption(rgb[1], caption_b);
    rgb_diff = add_caption(rgb_diff, caption_diff);
  }
  // The trio all or nothing: a failure on the second image left a mixed old and new set.
  const std::vector<PngText> text{software_png_text()};
  write_output_set({{paths.a, encode_png(rgb[0], paths.a, text)},
                    {paths.b, encode_png(rgb[1], paths.b, text)},
                    {paths.diff, encode_png(rgb_diff, paths.diff, text)}},
                   job.force);

  nlohmann::json figures = sides;
  figures["captions"] = {{"a", caption_a}, {"b", caption_b}, {"diff", caption_diff}};
  figures["scene"] = job.scene;
  figures["metric"] = job.metric;
  figures["width"] = size.width;
  figures["height"] = size.height;
  figures["scale_max"] = locked;
  figures["total_a"] = ab.total_a;
  figures["total_b"] = ab.total_b;
  // A side without counters (Embree) has an image of zeros: no comparison of counts (null), not "B cheaper
  // everywhere"; no ratio of a total of 0 (that, or an empty view) either.
  const bool counted = uncounted.empty();
  const auto if_counted = [&](const nlohmann::json& v) { return counted ? v : nlohmann::json(nullptr); };
  figures["total_diff"] = if_counted(ab.total_b - ab.total_a);
  figures["ratio_b_over_a"] =
      ab.total_a > 0.0 ? if_counted(nlohmann::json(ab.total_b / ab.total_a)) : nlohmann::json(nullptr);
  figures["max_abs_diff"] = if_counted(ab.max_abs_diff);
  figures["pixels_b_cheaper"] = if_counted(ab.b_cheaper);
  figures["pixels_b_dearer"] = if_counted(ab.b_dearer);
  figures["pixels_hit_changed"] = hits_changed(hits[0], hits[1]);  // hit vs miss, or another triangle
  figures["trace_ratio_b_over_a"] =
      sides["a"]["trace_ms"].get<double>() > 0.0
          ? nlohmann::json(sides["b"]["trace_ms"].get<double>() / sides["a"]["trace_ms"].get<double>())
          : nlohmann::json(nullptr);
  figures["out"] = {{"a", absolute_path(paths.a)}, {"b", absolute_path(paths.b)}, {"diff", absolute_path(paths.diff)}};
  std::cout << path_line(absolute_path(paths.a)) << "\n"
            << path_line(absolute_path(paths.b)) << "\n"
            << path_line(absolute_path(paths.diff)) << "\n";
  print_picture_line(figures);
  return 0;
}

}  // namespace accelviz::cli
