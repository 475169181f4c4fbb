// accelviz render: a per-pixel metric heatmap (nodes visited, primitive tests,
// cost, shading, depth) of one structure, written as a PNG with a legend.
// Also the no-subcommand demo, which renders the demo scene the same way.
#include <algorithm>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <span>

#include "app/cli_common.h"
#include "app/render_compare.h"
#include "app/render_raster.h"
#include "core/accel/bvh/bvh.h"
#include "core/accel/tlas/tlas.h"
#include "core/analysis/caption.h"
#include "core/analysis/heatmap.h"
#include "core/query/camera.h"
#include "core/scene/load.h"
#include "core/util/output_file.h"
#include "core/util/shell_quote.h"
#ifdef ACCELVIZ_HAVE_UI
#include "ui/gl/headless.h"
#include "ui/render/gpu_trace.h"
#endif

namespace accelviz::cli {

namespace {

/// A two-level structure's instanced (world) triangles beside `triangles`, the
/// flattened list's count, which is 0 for a scene too large to flatten.
void note_instanced_triangles(nlohmann::json& figures, const Accelerator& accel) {
  if (const auto* tlas = dynamic_cast<const Tlas*>(&accel))
    figures["instanced_triangles"] = tlas->instanced_triangles();
}

struct RenderOptions {
  std::string scene;
  std::string structure = "bvh";
  std::string metric = "nodes";
  std::string out;
  std::string camera;
  std::string size = "800x600";
  std::string colormap = "viridis";
  std::string legend = "bottom";
  std::string max_text;         ///< --max: "M" (a value) or "pNN" (the NNth percentile of the image's values)
  float max = 0.0f;             ///< parsed from max_text: a fixed top (0: none)
  double max_percentile = 0.0;  ///< parsed from max_text: the top at this percentile (0: none)
  unsigned threads = 0;
  std::string triangle_test = "watertight";
  bool force = false;
  std::string order = "front-to-back";  ///< child order: front-to-back, back-to-front, unordered
  bool xray = false;                    ///< count the full traversal as if no hit ended it
  std::optional<std::string> compare;   ///< B's differences from A (render --compare)
  StructureCli structure_opts;
  std::string view = "heatmap";
  RasterOptions raster;
  std::string ray_pixel;
  std::string ray_camera;         ///< the camera --ray-pixel's ray is cast from ("": the view's, --camera)
  std::string device = "cpu";     ///< where the heatmap's rays are traced: cpu, gpu (compute shader, bvh only)
  std::optional<std::string> gl;  ///< --device gpu's context: auto (default: EGL on a GPU, else OSMesa), egl, osmesa
  std::string caption = "auto";   ///< the strip under the heatmap: auto (render_caption), none, or this text
};

/// What the heatmap shows, as the command that draws it: the scene, the
/// structure, the metric, the size and every option that differs from its
/// default (not the output or the threads), each word quoted for the shell
/// where it needs it: on the picture, so that a heatmap pasted into a lecture
/// or a bug report still says what it is, and pasted back draws it again.
std::string render_caption(const RenderOptions& o) {
  const RenderOptions d;
  const StructureCli& s = o.structure_opts;
  const StructureCli& ds = d.structure_opts;
  // A file name starting with '-' would read as an option: ./ keeps it a name.
  const std::string scene = o.scene.starts_with("-") ? "./" + o.scene : o.scene;
  std::string c =
      "accelviz render " + shell_quote(scene) + " -s " + o.structure + " -m " + o.metric + " --size " + o.size;
  const auto add = [&c](bool differs, const std::string& text) {
    if (differs) c += " " + text;
  };
  add(!o.camera.empty(), "--camera " + shell_quote(o.camera));
  add(o.colormap != d.colormap, "--colormap " + o.colormap);
  add(o.legend != d.legend, "--legend " + o.legend);
  add(o.triangle_test != d.triangle_test, "--triangle-test " + o.triangle_test);
  add(o.order != d.order, "--order " + o.order);
  add(o.xray, "--xray");
  add(!o.max_text.empty(), "--max " + shell_quote(o.max_text));
  add(o.device != d.device, "--device " + o.device);
  if (o.structure == "bvh" || o.structure == "tlas") {
    add(s.splitter != ds.splitter, "--splitter " + s.splitter);
    add(s.buckets != ds.buckets, "--buckets " + std::to_string(s.buckets));
    add(s.leaf != ds.leaf, "--leaf " + std::to_string(s.leaf));
    add(s.leaf_cap != ds.leaf_cap, "--leaf-cap " + std::to_string(s.leaf_cap));
  }
  if (o.structure == "bvh" || o.structure == "tlas" || o.metric == "cost") {
    add(s.ctrav != ds.ctrav, "--ctrav " + number_text(s.ctrav));
    add(s.cisect != ds.cisect, "--cisect " + number_text(s.cisect));
  }
  if (o.structure == "embree") {
    add(s.embree_quality != ds.embree_quality, "--embree-quality " + s.embree_quality);
    add(s.embree_robust, "--embree-robust");
  }
  return c;
}

/// The text a heatmap's PNG carries: the command that draws it and the program.
std::vector<PngText> png_text_of(const RenderOptions& o) {
  return {{"Description", render_caption(o)}, software_png_text()};
}

/// --ray-pixel "X,Y".
std::pair<int, int> parse_pixel(const std::string& text) {
  const auto comma = text.find(',');
  try {
    if (comma == std::string::npos) throw std::invalid_argument("no comma");
    std::size_t used_x = 0, used_y = 0;
    const int x = std::stoi(text.substr(0, comma), &used_x);
    const int y = std::stoi(text.substr(comma + 1), &used_y);
    if (used_x != comma || used_y != text.size() - comma - 1) throw std::invalid_argument("trailing characters");
    return {x, y};
  } catch (const std::logic_error&) {
    throw UsageError("--ray-pixel: expected X,Y (two integers), got '" + text + "'");
  }
}

/// The structure and query options of the command line (render's one side, --compare's A).
CompareSide compare_side(const RenderOptions& o) {
  return CompareSide{o.structure, o.structure_opts, o.triangle_test, o.order, o.xray};
}

/// The overlay view through the GL renderer (OSMesa), written to o.out.
int run_render_raster(const RenderOptions& o, const GlobalOptions& global) {
  const ImageSize size = parse_size(o.size);
  Progress progress(global.quiet);
  const Scene scene = load_scene_with_progress(o.scene, global.quiet, progress);
  const Camera camera = camera_for(o.camera, scene, size);
  const std::unique_ptr<Accelerator> accel =
      build_with_progress(o.structure, scene, o.structure_opts.to_options(o.threads, /*compute_epo=*/false), progress);

  RasterOptions ro = o.raster;
  if (!o.ray_pixel.empty()) ro.ray_pixel = parse_pixel(o.ray_pixel);
  if (!o.ray_camera.empty()) {
    if (o.ray_pixel.empty()) throw UsageError("--ray-camera needs --ray-pixel");
    ro.ray_camera = camera_for(o.ray_camera, scene, size);  // seen from --camera: the ray's path, not a dot
  }
  QueryOptions query;
  query.triangle_test = parse_triangle_test(o.triangle_test);
  nlohmann::json figures = {{"scene", o.scene},
                            {"structure", o.structure},
                            {"width", size.width},
                            {"height", size.height},
                            {"triangles", scene.triangles.size()},
                            {"build_ms", accel->build_stats().build_ms}};
  note_instanced_triangles(figures, *accel);
  progress.begin("drawing the raster view");
  render_raster(scene, *accel, camera, size, ro, o.metric, o.colormap, o.max, query, o.structure_opts.ctrav,
                o.structure_opts.cisect, o.threads, o.out, o.force, figures);
  progress.end();
  const std::string abs = absolute_path(o.out);
  figures["out"] = abs;
  std::cout << path_line(abs) << "\n";
  print_picture_line(figures);
  return 0;
}

/// One structure's heatmap, traced and not yet coloured, with its figures.
struct TracedHeatmap {
  MetricImage image;
  nlohmann::json figures;
  bool counters = true;  ///< per-ray counters (Embree keeps none)
  std::string name;      ///< the accelerator's name
};

/// Builds o.structure over `scene` and traces its heatmap (CPU or GPU) from `camera`.
TracedHeatmap trace_heatmap(const RenderOptions& o, const Scene& scene, const Camera& camera,
                            const GlobalOptions& global, Progress& progress) {
  const ImageSize size = parse_size(o.size);
  const HeatMetric metric = parse_metric(o.metric).value();
  const auto t0 = Clock::now();
  const std::unique_ptr<Accelerator> accel =
      build_with_progress(o.structure, scene, o.structure_opts.to_options(o.threads, /*compute_epo=*/false), progress);
  const double build_wall_ms = ms_since(t0);

  HeatmapOptions ho = heatmap_options_of(compare_side(o), metric, size, o.threads);
  HeatmapFigures fig;
  MetricImage img;
  nlohmann::json gpu_figures;
#ifdef ACCELVIZ_HAVE_UI
  if (o.device == "gpu") {
    // Headless GL 4.5 (--gl: EGL on a GPU or OSMesa); the image size of the
    // context is irrelevant: the compute shader writes a storage buffer.
    progress.begin("compiling the trace shader, uploading the bvh");
    const std::unique_ptr<GlContext> gl = make_headless_context(1, 1, o.gl.value_or("auto"));
    const GlContext& context = *gl;
    const auto t_setup = Clock::now();
    GpuBvhTracer tracer;
    tracer.upload(dynamic_cast<const Bvh&>(*accel));
    const double setup_ms = ms_since(t_setup);
    progress.end(std::to_string(static_cast<long long>(setup_ms)) + " ms");
    progress.begin("rendering " + o.metric + " on the GPU (" + context.info().renderer + ")");
    double readback_ms = 0.0;
    img = gpu_render_metric(tracer, camera, ho, &fig, &readback_ms);
    progress.end(std::to_string(static_cast<long long>(fig.render_ms)) + " ms");
    gpu_figures = {{"gpu_renderer", context.info().renderer},
                   {"gpu_context", context.kind()},
                   {"gpu_setup_ms", setup_ms},
                   {"gpu_readback_ms", readback_ms}};
    if (context.kind() == "egl") gpu_figures["gpu_device_file"] = context.device_file();
  } else
#endif
  {
    progress.begin("rendering " + o.metric);
    ho.progress = progress.callback();
    img = render_metric(*accel, camera, ho, &fig);
    progress.end(std::to_string(static_cast<long long>(fig.render_ms)) + " ms");
  }

  TracedHeatmap t;
  nlohmann::json& figures = t.figures;
  figures = {
      {"scene", o.scene},
      {"structure", o.structure},
      {"metric", o.metric},
      {"width", size.width},
      {"height", size.height},
      {"triangles", scene.triangles.size()},
      {"build_ms", accel->build_stats().build_ms},
      {"build_wall_ms", build_wall_ms},
      {"render_ms", fig.render_ms},
      {"rays", fig.rays},
      {"hits", fig.hits},
      {"rays_per_s", fig.rays_per_s},
      {"mean", fig.mean},
      {"max", fig.max},
      {"colormap", o.colormap},
      {"camera",
       {{"eye", {camera.position.x, camera.position.y, camera.position.z}},
        {"forward", {camera.forward.x, camera.forward.y, camera.forward.z}},
        {"yfov_deg", camera.yfov * 180.0 / 3.14159265358979}}},
  };
  note_instanced_triangles(figures, *accel);
  // render_ms includes counting for the counter metrics; Embree keeps no
  // per-ray counters (its nodes/prims/cost images are all 0), so nothing was counted.
  const bool counters = accel->inspectable();
  figures["per_ray_counters"] = counters;
  if (metric_needs_stats(metric)) {
    figures["instrumented"] = counters;
    if (!counters && !global.quiet)
      std::cerr << "accelviz: embree keeps no per-ray counters: its " << o.metric << " image is all 0\n";
  }
  figures["device"] = o.device;
  for (const auto& [key, value] : gpu_figures.items()) figures[key] = value;
  t.image = std::move(img);
  t.counters = counters;
  t.name = accel->name();
  return t;
}

/// The colour options of o (map, legend, the structure's words) with the scale's top: --max's
/// value, or its percentile of `images`, or 0 (each image's own maximum).
ColorizeOptions colour_options(const RenderOptions& o, std::span<const MetricImage* const> images) {
  ColorizeOptions co;
  co.map = parse_colormap(o.colormap).value();
  co.max = o.max;
  if (o.max_percentile > 0.0) {  // --max pNN: the top where NN % of the pixels' values lie below
    co.max = metric_percentile(images, o.max_percentile);
    co.scale_note = "top: " + ordinal(o.max_percentile) + " percentile";
  }
  co.legend = parse_legend_placement(o.legend).value();
  co.structure = o.structure;  // the legend in its words: a grid's nodes are cells
  return co;
}

/// `t` coloured under `co`, with the notes of what it cannot show; its figures get scale_max.
RgbImage colour_heatmap(const RenderOptions& o, TracedHeatmap& t, const ColorizeOptions& co) {
  const HeatMetric metric = parse_metric(o.metric).value();
  t.figures["scale_max"] = heatmap_scale_max(t.image, co.max);
  RgbImage rgb = colorize(t.image, co);
  // All 0 because nothing was counted, not because nothing was visited: the image says so itself.
  if (metric_needs_stats(metric) && !t.counters)
    draw_note(rgb, "n/a: " + t.name + " counts nothing per ray");
  else if (const std::string why = metric_not_counted(metric, o.structure); !why.empty())
    draw_note(rgb, "n/a: " + why);
  return rgb;
}

/// Loads, builds, renders and colours; returns the image and the figures as JSON.
RgbImage render_job(const RenderOptions& o, const GlobalOptions& global, nlohmann::json& figures) {
  Progress progress(global.quiet);
  const Scene scene = load_scene_with_progress(o.scene, global.quiet, progress);
  const Camera camera = camera_for(o.camera, scene, parse_size(o.size));
  TracedHeatmap t = trace_heatmap(o, scene, camera, global, progress);
  const MetricImage* images[] = {&t.image};
  const RgbImage rgb = colour_heatmap(o, t, colour_options(o, images));
  figures = std::move(t.figures);
  return rgb;
}

/// render -s A,B,...: one image per structure, DIR/NAME-A.png, ..., on one colour scale (the
/// largest of their maxima, or --max), so that a lecture's pictures of one view compare by colour.
int run_render_several(const RenderOptions& o, const std::vector<std::string>& structures,
                       const GlobalOptions& global) {
  const HeatMetric metric = parse_metric(o.metric).value();
  if (!metric_needs_stats(metric))
    throw UsageError(
        "several structures: a cost metric (nodes, prims, cost or instances) shares a scale, not --metric " + o.metric);
  if (o.view != "heatmap") throw UsageError("several structures: --view heatmap only");
  if (o.device != "cpu") throw UsageError("several structures: --device cpu only");
  std::vector<RenderOptions> each;
  for (const std::string& s : structures) {
    RenderOptions os = o;
    os.structure = s;
    if (const std::string problem = order_problem(compare_side(os)); !problem.empty())
      throw UsageError(s + ": " + problem);
    const std::filesystem::path p(o.out);
    os.out = (p.parent_path() / (p.stem().string() + "-" + s + p.extension().string())).string();
    check_output_path(os.out, o.force);
    each.push_back(std::move(os));
  }
  Progress progress(global.quiet);
  const Scene scene = load_scene_with_progress(o.scene, global.quiet, progress);
  const Camera camera = camera_for(o.camera, scene, parse_size(o.size));
  std::vector<TracedHeatmap> traced;
  for (const RenderOptions& os : each) traced.push_back(trace_heatmap(os, scene, camera, global, progress));
  // One scale over the images that count something: a structure that counts nothing per ray (embree;
  // the voxels' prims) is all 0, and its zeros pulled a shared percentile down (p90: 10 read 2).
  std::vector<const MetricImage*> images;
  for (std::size_t i = 0; i < traced.size(); ++i)
    if (traced[i].counters && metric_not_counted(metric, each[i].structure).empty()) images.push_back(&traced[i].image);
  // --max's value, or its percentile of those images' values together, else their largest maximum.
  ColorizeOptions shared = colour_options(o, images);
  if (o.max_percentile > 0.0) {
    shared.max = heatmap_scale_max(ValueRange{0.0f, shared.max}, 0.0f);  // all 0: a top of 1, as --compare
  } else if (!(shared.max > 0.0f)) {
    for (const MetricImage* img : images) shared.max = std::max(shared.max, heatmap_scale_max(*img, 0.0f));
    if (!(shared.max > 0.0f)) shared.max = 1.0f;  // nothing counted anywhere
  }
  nlohmann::json out = {{"scene", o.scene}, {"metric", o.metric}, {"scale_max", shared.max}};
  out["images"] = nlohmann::json::array();
  std::vector<OutputBytes> files;  // written all or nothing once every image is ready
  for (std::size_t i = 0; i < each.size(); ++i) {
    const RenderOptions& os = each[i];
    ColorizeOptions co = shared;
    co.structure = os.structure;
    co.title_prefix = os.structure + ": ";
    std::string others;
    for (const std::string& s : structures)
      if (s != os.structure) others += (others.empty() ? "" : ", ") + s;
    co.scale_note = (shared.scale_note.empty() ? "" : shared.scale_note + "; ") + "scale shared with " + others;
    RgbImage rgb = colour_heatmap(os, traced[i], co);
    nlohmann::json& figures = traced[i].figures;
    // The single-structure command that draws the same picture: its --max is the shared top.
    RenderOptions alone = os;
    if (o.max_percentile > 0.0 || o.max_text.empty()) alone.max_text = number_text(shared.max);
    if (o.caption != "none") {
      figures["caption"] = o.caption == "auto" ? render_caption(alone) : o.caption;
      rgb = add_caption(rgb, figures["caption"].get<std::string>());
    }
    files.push_back({os.out, encode_png(rgb, os.out, png_text_of(alone))});
    figures["out"] = absolute_path(os.out);
    out["images"].push_back(figures);
  }
  write_output_set(files, o.force);
  for (const nlohmann::json& figures : out["images"]) std::cout << path_line(figures["out"].get<std::string>()) << "\n";
  print_picture_line(out);
  return 0;
}

int run_render(const RenderOptions& given, const GlobalOptions& global) {
  RenderOptions o = given;
  if (!o.max_text.empty()) parse_scale_top(o.max_text, o.max, o.max_percentile);
  if (o.view == "raster" && o.max_percentile > 0.0)
    throw UsageError("--max " + o.max_text + ": a percentile top is for the heatmap view; give --view raster a value");
  if (const std::string problem = png_name_problem(o.out); !problem.empty()) throw UsageError(problem);
  if (o.gl && o.device != "gpu") throw UsageError("--gl needs --device gpu");
  if (o.device == "gpu") {
#ifndef ACCELVIZ_HAVE_UI
    throw UsageError(needs_renderer("--device gpu"));
#else
    if (const std::string why = gpu_trace_unsupported(o.structure); !why.empty())
      throw UsageError("--device gpu: " + why);
    if (o.compare) throw UsageError("--device gpu: --compare traces on the CPU only");
    if (o.view != "heatmap") throw UsageError("--device gpu needs --view heatmap");
#endif
  }
  if (!o.compare) o.structure_opts.say_unused(comma_items(o.structure), o.metric == "cost", global.quiet);
  if (o.structure.find(',') != std::string::npos) {
    if (o.compare) throw UsageError("--compare: one structure for A (B names its own: structure=...)");
    return run_render_several(o, comma_items(o.structure), global);  // checked when parsed
  }
  if (const std::string problem = order_problem(compare_side(o)); !problem.empty()) throw UsageError(problem);
  if (o.compare) {
    if (o.view != "heatmap") throw UsageError("--compare needs --view heatmap");
    CompareJob job{o.scene, o.camera, o.size, o.metric, o.colormap, o.legend, o.max, o.threads, o.out, o.force, {}, {}};
    job.max_percentile = o.max_percentile;
    job.a = compare_side(o);
    job.b = parse_compare_spec(*o.compare, job.a);
    // Options that do not fit together, said for the side they belong to.
    (void)job.a.structure_opts.to_options(1, false);
    try {
      (void)job.b.structure_opts.to_options(1, false);
    } catch (const UsageError& e) {
      throw UsageError(std::string("--compare: B: ") + e.what());
    }
    if (const std::string problem = order_problem(job.b); !problem.empty())
      throw UsageError("--compare: B (" + job.b.structure + "): " + problem);
    return run_render_compare(job, global);
  }
  check_output_path(o.out, o.force);  // before any long work
  if (o.view == "raster" && !raster_available()) throw UsageError(needs_renderer("--view raster"));
  if (o.view == "raster") return run_render_raster(o, global);
  if (o.raster.box_depth >= 0 || o.raster.box_depth_last >= 0 || o.raster.leaves || !o.ray_pixel.empty() ||
      !o.ray_camera.empty() || o.raster.blend > 0.0f || o.raster.wireframe)
    throw UsageError(
        "--depth, --depth-last, --leaves, --ray-pixel, --ray-camera, --blend and --wireframe need --view raster");
  nlohmann::json figures;
  RgbImage rgb = render_job(o, global, figures);
  if (o.caption != "none") {
    figures["caption"] = o.caption == "auto" ? render_caption(o) : o.caption;
    rgb = add_caption(rgb, figures["caption"].get<std::string>());
  }
  // The command that draws it and the build, in the file (a caption cut on a small picture, or none).
  std::vector<PngText> text = png_text_of(o);
  if (o.caption != "auto" && o.caption != "none") text.push_back({"Comment", o.caption});  // the strip's own text
  write_png(o.out, rgb, o.force, text);
  const std::string abs = absolute_path(o.out);
  figures["out"] = abs;
  std::cout << path_line(abs) << "\n";
  print_picture_line(figures);
  return 0;
}

/// accelviz-demo-YYYYmmdd-HHMMSS[-k].png in the current directory, never an existing file.
std::string write_unique_demo_png(const RgbImage& rgb, std::span<const PngText> text) {
  namespace fs = std::filesystem;
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  localtime_r(&now, &tm);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &tm);
  for (int k = 0; k < 1000; ++k) {
    const std::string name = std::string("accelviz-demo-") + stamp + (k == 0 ? "" : "-" + std::to_string(k)) + ".png";
    if (name_taken(name)) continue;  // a dangling link too: the write refuses it
    try {
      write_png(name, rgb, /*overwrite=*/false, text);
      return name;
    } catch (const std::runtime_error&) {
      if (name_taken(name)) continue;  // another process took the name in between
      throw;
    }
  }
  throw std::runtime_error(std::string("accelviz-demo-") + stamp + "-*.png: no free file name");
}

}  // namespace

Command add_render_command(CLI::App& parent, const GlobalOptions& global) {
  auto o = std::make_shared<RenderOptions>();
  CLI::App* sub = parent.add_subcommand("render",
                                        "Render a per-pixel metric heatmap of a structure to a PNG "
                                        "(with a legend bar)");
  sub->add_option("SCENE", o->scene, "Scene file (.gltf, .glb, .obj) or builtin:NAME[?key=value&...]")->required();
  sub->add_option("--out,-o", o->out, "Output PNG file (never overwritten without --force)")->required();
  sub->add_option("--structure,-s", o->structure,
                  "Acceleration structure; a comma-separated list (bvh,kdtree,grid) writes OUT-bvh.png, "
                  "OUT-kdtree.png, ... on one colour scale (a cost metric, the heatmap view)")
      ->check(CLI::Validator([](std::string& text) { return name_list_problem(text, structure_names()); },
                             "NAME[,NAME...]"))
      ->capture_default_str();
  sub->add_option("--metric,-m", o->metric,
                  "Per-pixel metric: nodes (nodes visited), prims (triangle tests), cost (ctrav*nodes + "
                  "cisect*prims), shaded (headlight shading), depth (hit distance), instances (instances "
                  "visited, two-level structure)")
      ->check(CLI::IsMember({"nodes", "prims", "cost", "shaded", "depth", "instances"}))
      ->capture_default_str();
  sub->add_option(
      "--camera", o->camera,
      "View: ex,ey,ez,tx,ty,tz[,fovdeg] (eye, target, vertical fov in degrees, default 45) or gltf:N "
      "(the scene's N-th camera); default: the scene's first camera, else a view framing the scene (vertical fov "
      "0.8 rad, 45.84 degrees)");
  sub->add_option("--size", o->size, "Image size WxH (the legend is added below or beside it)")
      ->check(size_validator())
      ->capture_default_str();
  sub->add_option("--colormap", o->colormap, "Colour map: viridis, inferno, turbo")
      ->check(CLI::IsMember({"viridis", "inferno", "turbo"}))
      ->capture_default_str();
  sub->add_option("--max", o->max_text,
                  "Top of the colour scale: a value, or pNN for the NNth percentile of the image's values (p99: a "
                  "few outliers do not set it); default: the image's maximum; values above are clamped")
      ->option_text("M|pNN");
  sub->add_option("--legend", o->legend, "Legend bar placement: bottom, right, none")
      ->check(CLI::IsMember({"bottom", "right", "none"}))
      ->capture_default_str();
  add_threads_option(sub, o->threads, "Threads for building and tracing (0: all hardware threads)");
  add_triangle_test_option(sub, o->triangle_test);
  sub->add_flag("--force,-f", o->force, "Overwrite an existing output file");
  sub->add_option("--order", o->order,
                  "Child order of the traversal: front-to-back, back-to-front (the worst order), unordered (a fixed "
                  "order); bvh and tlas take all three, kdtree and octree front-to-back and unordered")
      ->check(CLI::IsMember({"front-to-back", "back-to-front", "unordered"}))
      ->capture_default_str();
  sub->add_flag("--xray", o->xray,
                "Count the full traversal as if no hit ended it (no culling behind the closest hit; bvh and tlas)");
  sub->add_option("--compare", o->compare,
                  "A/B: render A (these options) and B (A with these changes, e.g. 'structure=bvh buckets=4' or "
                  "'order=unordered'; keys: structure splitter buckets leaf leaf-cap ctrav cisect embree-quality "
                  "triangle-test order xray) and write OUT-a.png, OUT-b.png (one locked colour scale) and "
                  "OUT-diff.png (B - A, diverging colours)");
  sub->add_option("--view", o->view,
                  "heatmap: the per-pixel metric image traced on the CPU; raster: the overlay view drawn by the "
                  "OpenGL renderer headless (mesh, node boxes, a ray path, heatmap blend)")
      ->check(CLI::IsMember({"heatmap", "raster"}))
      ->capture_default_str();
  // A range, not NonNegativeNumber: its message printed the 309 digits of DBL_MAX.
  sub->add_option("--depth", o->raster.box_depth, "raster: draw the BVH node boxes at this depth (root = 0)")
      ->check(CLI::Range(0, 1 << 20));
  sub->add_option("--depth-last", o->raster.box_depth_last,
                  "raster: with --depth, draw every depth from --depth to this one (inclusive)")
      ->check(CLI::Range(0, 1 << 20));
  sub->add_flag("--leaves", o->raster.leaves, "raster: draw every leaf box");
  sub->add_option("--ray-pixel", o->ray_pixel,
                  "raster: draw the primary ray of pixel X,Y (row 0 at the top): its path, hit, normal, the boxes "
                  "it entered in order and the primitives it tested");
  sub->add_option("--ray-camera", o->ray_camera,
                  "raster: cast --ray-pixel's ray from this camera (as --camera reads it) while --camera shows the "
                  "view: the ray's path from the side, not a dot where it leaves the eye");
  sub->add_option("--blend", o->raster.blend,
                  "raster: blend the --metric heatmap over the mesh with this opacity (0: none, 1: full screen)")
      ->check(finite_range(0.0, 1.0));
  sub->add_flag("--wireframe", o->raster.wireframe, "raster: draw triangle edges over the mesh");
  sub->add_option("--device", o->device,
                  "Where the heatmap's rays are traced: cpu (all threads), gpu (an OpenGL 4.5 compute shader "
                  "in a headless context, see --gl; --structure bvh only; same counts as the CPU)")
      ->check(CLI::IsMember({"cpu", "gpu"}))
      ->capture_default_str();
  sub->add_option("--gl", o->gl,
                  "--device gpu's headless OpenGL context: auto (the default: EGL on a GPU when the machine has "
                  "one, else OSMesa), egl (EGL on a device: a GPU, else Mesa's software device), osmesa (llvmpipe)")
      ->check(CLI::IsMember({"auto", "egl", "osmesa"}));
  sub->add_option("--caption", o->caption,
                  "heatmap: a strip under the picture that says what it shows: auto (the command line that draws it: "
                  "scene, structure, metric, size and every option not at its default), none, or this text")
      ->capture_default_str();
  o->structure_opts.add_to(sub);
  return {sub, [o, &global] { return run_render(*o, global); }};
}

int run_demo(const GlobalOptions& global) {
  RenderOptions o;
  o.scene = kDemoScene;
  o.structure = "bvh";
  o.metric = "nodes";
  nlohmann::json figures;
  const RgbImage rgb = add_caption(render_job(o, global, figures), render_caption(o));
  figures["caption"] = render_caption(o);  // the command that draws the same picture
  const std::string abs = absolute_path(write_unique_demo_png(rgb, png_text_of(o)));
  figures["out"] = abs;
  std::cout << "No display: rendered the demo heatmap to " << path_line(abs) << "\n" << path_line(abs) << "\n";
  print_picture_line(figures);
  return 0;
}

}  // namespace accelviz::cli
