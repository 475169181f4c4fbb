#include "app/cli_common.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <thread>

#include "app/build_info.h"
#include "core/accel/embree_backend.h"
#include "core/analysis/heatmap.h"
#include "core/analysis/sah.h"
#include "core/query/camera.h"
#include "core/scene/effects.h"
#include "core/scene/load.h"
#include "core/util/file_checks.h"
#include "core/util/json_text.h"
#include "core/util/output_file.h"
#include "core/util/shell_quote.h"

namespace accelviz::cli {

namespace fs = std::filesystem;

ImageSize parse_size(const std::string& text) {
  if (const std::optional<ImageSize> size = parse_image_size(text)) return *size;
  throw UsageError("size '" + text + "': expected WxH with each side in 1.." + std::to_string(kMaxImageSide) +
                   ", e.g. 800x600");
}

CLI::Validator size_validator() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        try {
          parse_size(value);
          return {};
        } catch (const UsageError& e) {
          return e.what();
        }
      },
      "WxH", "size");
}

void StructureCli::add_to(CLI::App* app, bool with_embree) {
  bvh_options_.clear();
  embree_options_.clear();
  const auto bvh = [this](CLI::Option* opt) { bvh_options_.push_back(opt); };
  const auto embree = [this](CLI::Option* opt) { embree_options_.push_back(opt); };
  bvh(app->add_option("--splitter", splitter,
                      "BVH split strategy: binned (binned SAH), exact (full SAH sweep), median, lbvh (Morton codes)")
          ->check(CLI::IsMember({"binned", "exact", "median", "lbvh"}))
          ->capture_default_str()
          ->group("Structure"));
  bvh(app->add_option("--buckets", buckets, "BVH binned-SAH bucket count")
          ->check(CLI::Range(2, 256))
          ->capture_default_str()
          ->group("Structure"));
  bvh(app->add_option("--leaf", leaf, "BVH: nodes with at most this many triangles always become leaves")
          ->check(CLI::Range(1, 255))
          ->capture_default_str()
          ->group("Structure"));
  bvh(app->add_option("--leaf-cap", leaf_cap,
                      "BVH: SAH may keep up to this many triangles in a leaf when cheaper (at least --leaf; raised to "
                      "--leaf when not given)")
          ->check(CLI::Range(1, 255))
          ->each([this](const std::string&) { leaf_cap_given = true; })
          ->capture_default_str()
          ->group("Structure"));
  bvh(app->add_option("--ctrav", ctrav, "SAH cost of visiting an inner node (C_trav)")
          ->check(cost_constant())
          ->capture_default_str()
          ->group("Structure"));
  bvh(app->add_option("--cisect", cisect, "SAH cost of one ray-triangle test (C_isect)")
          ->check(cost_constant())
          ->capture_default_str()
          ->group("Structure"));
  bvh(app->add_option("--wide", wide,
                      "BVH fast path: width of the SIMD tree the uninstrumented queries walk: 0 = 8 (AVX2) where the "
                      "CPU has AVX2 and FMA, else 4 (SSE); 4; 8 (4 without AVX2 and FMA)")
          ->check(CLI::IsMember({0, 4, 8}))
          ->capture_default_str()
          ->group("Structure"));
  if (!with_embree) return;
  embree(app->add_option("--embree-quality", embree_quality, "Embree build quality: low, medium, high")
             ->check(CLI::IsMember({"low", "medium", "high"}))
             ->capture_default_str()
             ->group("Structure"));
  embree(app->add_flag("--embree-robust", embree_robust,
                       "Embree robust mode (RTC_SCENE_FLAG_ROBUST: no optimisations that lose watertightness), the "
                       "counterpart of our watertight triangle test")
             ->group("Structure"));
  embree(
      app->add_option("--embree-isa", embree_isa,
                      "Embree's kernels: auto (its own choice, the widest the CPU has), sse2, sse4.2, avx, avx2 (our "
                      "fast path's), avx512")
          ->check(CLI::IsMember([] {
            std::vector<std::string> names;  // embree_isa_name's
            for (EmbreeIsa isa : kEmbreeIsas) names.emplace_back(embree_isa_name(isa));
            return names;
          }()))
          ->capture_default_str()
          ->group("Structure"));
}

std::string StructureCli::unused_note(const std::vector<std::string>& structures, bool cost_metric) const {
  bool bvh = false, embree = false;
  for (const std::string& s : structures) {
    bvh = bvh || s == "bvh" || s == "tlas";
    embree = embree || s == "embree";
  }
  std::string names;
  const auto note = [&](const CLI::Option* opt) {
    if (opt->count() > 0) names += (names.empty() ? "" : ", ") + opt->get_name();
  };
  for (const CLI::Option* opt : bvh_options_) {
    const bool cost = opt->get_name() == "--ctrav" || opt->get_name() == "--cisect";
    if (!bvh && !(cost && cost_metric)) note(opt);
  }
  for (const CLI::Option* opt : embree_options_)
    if (!embree) note(opt);
  if (names.empty()) return {};
  std::string list;
  for (const std::string& s : structures) list += (list.empty() ? "" : ", ") + s;
  return list + (structures.size() == 1 ? " does" : " do") + " not use " + names +
         " (the BVH's options act on bvh and tlas, --ctrav and --cisect also on the cost metric, --embree-* on "
         "embree)";
}

void StructureCli::say_unused(const std::vector<std::string>& structures, bool cost_metric, bool quiet) const {
  if (const std::string note = unused_note(structures, cost_metric); !note.empty() && !quiet)
    std::fprintf(stderr, "accelviz: note: %s\n", note.c_str());
}

StructureOptions StructureCli::to_options(unsigned threads, bool compute_epo) const {
  StructureOptions o;
  o.threads = threads;
  o.bvh.splitter = splitter == "exact"    ? BvhSplitter::exact_sah
                   : splitter == "median" ? BvhSplitter::median
                   : splitter == "lbvh"   ? BvhSplitter::lbvh
                                          : BvhSplitter::binned_sah;
  o.bvh.buckets = buckets;
  o.bvh.max_leaf_size = leaf;
  // The cap can never be below the always-leaf size: raised with --leaf unless given.
  if (leaf_cap_given && leaf_cap < leaf)
    throw UsageError("--leaf-cap " + std::to_string(leaf_cap) + " is below --leaf " + std::to_string(leaf) +
                     " (nodes of at most --leaf triangles always become leaves; the cap is the largest leaf the SAH "
                     "may keep)");
  o.bvh.leaf_size_cap = std::max(leaf, leaf_cap);
  o.bvh.cost_traversal = ctrav;
  o.bvh.cost_intersect = cisect;
  o.bvh.compute_epo = compute_epo;
  o.bvh.wide_width = wide;
  o.embree.quality = parse_embree_quality(embree_quality).value_or(EmbreeQuality::medium);
  o.embree.robust = embree_robust;
  o.embree.isa = parse_embree_isa(embree_isa).value_or(EmbreeIsa::automatic);
  return o;
}

Camera camera_for(const std::string& spec, const Scene& scene, const ImageSize& size, bool has_camera_option) {
  try {
    return camera_from_spec(spec, scene, static_cast<float>(size.width) / static_cast<float>(size.height));
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--camera: ") + e.what());
  } catch (const std::range_error& e) {  // the framing camera of a scene near the float range: not a usage error
    throw std::runtime_error(
        scene.source + ": " + e.what() +
        (has_camera_option ? " (give a camera with --camera)" : " (this command has no --camera)"));
  }
}

TriangleTest parse_triangle_test(const std::string& name) {
  if (name == "watertight") return TriangleTest::watertight;
  if (name == "fast") return TriangleTest::moller_trumbore;
  throw UsageError("triangle test '" + name + "': expected watertight or fast");
}

CLI::Option* add_triangle_test_option(CLI::App* sub, std::string& value, const char* help) {
  return sub
      ->add_option("--triangle-test", value,
                   help ? help : "Ray-triangle test: watertight (Woop et al. 2013) or fast (Moller-Trumbore)")
      ->check(CLI::IsMember({"watertight", "fast"}))
      ->capture_default_str();
}

namespace {

/// The number an option's text holds, if it is one (with nothing after it).
bool option_number(const std::string& text, double& value) {
  std::size_t used = 0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    return false;
  }
  return used == text.size();
}

}  // namespace

std::string number_text(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", x);
  return buf;
}

CLI::Validator finite_positive() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        double v = 0.0;
        // A float: 1e300 is inf there, and "must be finite" read oddly for a finite number.
        if (!option_number(text, v) || !(v >= 1.2e-38 && v <= 3.4e38))
          return "must be a number from 1.2e-38 to 3.4e38 (float's range), got " + text;
        return {};
      },
      "POSITIVE");
}

CLI::Validator cost_constant() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        double v = 0.0;
        if (!option_number(text, v)) return "expected a number from 1e-06 to 1e+06, got '" + text + "'";
        if (const std::string problem = cost_constant_problem(v); !problem.empty()) return problem + ", got " + text;
        return {};
      },
      "[1e-06 - 1e+06]");
}

CLI::Validator finite_range(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        double v = 0.0;
        if (!option_number(text, v)) return "expected a number, got '" + text + "'";
        if (!std::isfinite(v) || v < lo || v > hi)
          return "must be a number from " + number_text(lo) + " to " + number_text(hi) + ", got " + text;
        return {};
      },
      "[" + number_text(lo) + " - " + number_text(hi) + "]");
}

CLI::Option* add_threads_option(CLI::App* sub, unsigned& value, const char* help) {
  return sub->add_option("--threads,-j", value, help)->check(CLI::Range(0u, kMaxThreads))->capture_default_str();
}

void require_flattened(const Scene& scene, const std::string& spec, const char* command) {
  if (scene.triangles.empty() && !scene.instances.empty())
    throw std::runtime_error(spec + ": instanced and too large to flatten; " + command +
                             " measures the flattened triangles (only 'tlas' can hold this scene: render, bench, "
                             "animate or flatten with -s tlas)");
}

std::string level_note(const Scene& scene, const std::string& structure) {
  if (structure == "brute" || structure == "brute-bbox") return {};  // no structure to speak of
  const Effect two_level = decide_effects(scene).two_level;
  if (two_level.on && structure != "tlas")
    return scene.source + ": " + two_level.reason + ": `-s tlas` builds the two-level structure it calls for; " +
           structure + " flattens its instances";
  if (!two_level.on && structure == "tlas")
    return scene.source + ": no mesh is instanced twice (two-level off): tlas holds its " +
           count_of(std::max<std::size_t>(1, scene.instances.size()), "instance");
  return {};
}

Scene load_scene_noting_warnings(const std::string& spec, bool quiet) {
  Scene scene = load_scene(spec);
  if (!quiet && !scene.report.warnings.empty())
    std::fprintf(stderr, "accelviz: %s: %zu loader warning(s); `accelviz info` lists them\n", spec.c_str(),
                 scene.report.warnings.size());
  return scene;
}

Scene load_scene_with_progress(const std::string& spec, bool quiet, Progress& progress) {
  progress.begin("loading " + spec);
  Scene scene = load_scene_noting_warnings(spec, quiet);
  progress.end(count_of(scene.triangles.size(), "triangle"));
  return scene;
}

std::unique_ptr<Accelerator> build_with_progress(const std::string& structure, const Scene& scene, StructureOptions so,
                                                 Progress& progress, const std::string& label) {
  if (const std::string note = level_note(scene, structure); !note.empty() && !progress.quiet())
    std::fprintf(stderr, "accelviz: note: %s\n", note.c_str());
  progress.begin("building " + (label.empty() ? structure : label));
  so.scene = &scene;
  std::unique_ptr<Accelerator> accel = build_accelerator(structure, scene.triangles, so, progress.callback());
  progress.end(std::to_string(static_cast<long long>(accel->build_stats().build_ms)) + " ms");
  return accel;
}

namespace {

/// Why files cannot be made in the folder `dir`, or its nearest existing
/// parent where it does not exist yet ("" when they can): checked before
/// the work, which ran to its end before the write failed (a read-only folder).
std::string unwritable_folder(const fs::path& dir) {
  std::error_code ec;
  fs::path d = dir.empty() ? fs::path(".") : dir;
  while (!fs::exists(d, ec) && d.has_parent_path() && d.parent_path() != d) d = d.parent_path();
  if (!fs::exists(d, ec)) d = ".";
  if (::access(d.c_str(), W_OK | X_OK) != 0) return "cannot write in " + d.string() + ": " + std::strerror(errno);
  return "";
}

}  // namespace

/// "" unless `path` is a symbolic link whose target does not exist: then the problem, said before the
/// work (a write through it failed only after the work, "cannot create directory" without a reason).
static std::string dangling_link_problem(const fs::path& path) {
  std::error_code ec;
  if (!fs::is_symlink(fs::symlink_status(path, ec)) || fs::exists(path, ec)) return {};
  const fs::path target = fs::read_symlink(path, ec);
  return "is a symbolic link to " + target.string() + ", which does not exist";
}

void check_output_dir(const std::string& dir, const OutputDirFiles& files, bool force) {
  if (dir.empty()) throw std::runtime_error("the output folder's name is empty");
  if (const std::string problem = dangling_link_problem(dir); !problem.empty())
    throw std::runtime_error(dir + ": " + problem);
  if (const std::string problem = name_length_problem(dir); !problem.empty())
    throw std::runtime_error(dir + ": " + problem);
  bool holds = false;
  if (const std::string problem = OutputFolder::problem(dir, files.names, force, &holds); !problem.empty()) {
    if (holds) throw std::runtime_error(dir + ": already holds " + files.label + " files (use --force to overwrite)");
    throw std::runtime_error(dir + ": " + problem);  // "DIR: sweep.csv: is not a regular file (...)"
  }
  if (const std::string problem = unwritable_folder(dir); !problem.empty())
    throw std::runtime_error(dir + ": " + problem);
}

OutputDirWriter::OutputDirWriter(const std::string& dir, const OutputDirFiles& files, bool force)
    : label_(files.label), folder_(dir, files.names, force) {
  check_output_dir(dir, files, force);  // again: the folder may have changed during the work
  if (const OutputWrite w = folder_.open(); !w.ok()) throw std::runtime_error(w.path + ": " + w.problem);
}

void OutputDirWriter::add(const std::string& name, const std::string& bytes) {
  if (const OutputWrite w = folder_.add(name, {bytes}); !w.ok()) throw std::runtime_error(w.path + ": " + w.problem);
}

void OutputDirWriter::commit() {
  if (const OutputWrite w = folder_.commit(); !w.ok()) throw std::runtime_error(w.path + ": " + w.problem);
  for (const std::string& left : folder_.stale_left())
    std::fprintf(stderr, "accelviz: warning: could not remove an earlier run's %s file: %s\n", label_.c_str(),
                 left.c_str());
}

void write_output_set(const std::vector<OutputBytes>& files, bool force) {
  const OutputWrite w = write_output_files(files, force);
  if (w.exists) throw std::runtime_error(w.path + ": exists (use --force to overwrite)");
  if (!w.ok()) throw std::runtime_error(w.path + ": " + w.problem);
}

void check_output_path(const std::string& path, bool force) {
  std::error_code ec;
  const fs::path p(path);
  if (const std::string problem = output_path_problem(path); !problem.empty())
    throw std::runtime_error(path + ": " + problem);
  if (!force && fs::exists(p, ec)) throw std::runtime_error(path + ": exists (use --force to overwrite)");
  // With --force a symbolic link is written through: the file it names must be able to exist.
  if (force && fs::is_symlink(fs::symlink_status(p, ec))) {
    fs::path target = fs::read_symlink(p, ec);
    if (!ec && target.is_relative()) target = (p.has_parent_path() ? p.parent_path() : fs::path(".")) / target;
    const fs::path target_dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    if (!ec && !fs::is_directory(target_dir, ec))
      throw std::runtime_error(path + ": is a symbolic link to " + target.string() + ", whose directory " +
                               target_dir.string() + " does not exist");
  }
  const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  if (!fs::is_directory(dir, ec)) throw std::runtime_error(path + ": directory " + dir.string() + " does not exist");
  if (const std::string problem = unwritable_folder(dir); !problem.empty())
    throw std::runtime_error(path + ": " + problem);
}

std::string absolute_path(const std::string& path) {
  std::error_code ec;
  const fs::path abs = fs::absolute(path, ec);
  return ec ? path : abs.lexically_normal().string();
}

std::string path_line(const std::string& path) {
  std::string line = path;
  for (char& c : line)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F) c = '?';
  return line;
}

std::vector<std::string> comma_items(const std::string& text) {
  std::vector<std::string> items;
  std::size_t start = 0;
  for (std::size_t comma; (comma = text.find(',', start)) != std::string::npos; start = comma + 1)
    items.push_back(text.substr(start, comma - start));
  items.push_back(text.substr(start));
  return items;
}

std::string braced_names(const std::vector<std::string>& names) {
  std::string all;
  for (const std::string& n : names) all += (all.empty() ? "" : ",") + n;
  return "{" + all + "}";
}

std::string name_list_problem(const std::string& text, const std::vector<std::string>& names) {
  const std::vector<std::string> items = comma_items(text);
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (items[i].empty()) return "an empty item in '" + text + "'";
    if (std::find(names.begin(), names.end(), items[i]) == names.end())
      return items[i] + " not in " + braced_names(names);
    if (std::find(items.begin(), items.begin() + static_cast<std::ptrdiff_t>(i), items[i]) !=
        items.begin() + static_cast<std::ptrdiff_t>(i))
      return "'" + items[i] + "' is listed twice";
  }
  return {};
}

namespace {

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) {
      const std::size_t c = line.find(':');
      if (c != std::string::npos && c + 1 < line.size()) {
        const std::size_t first = line.find_first_not_of(' ', c + 1);
        if (first != std::string::npos) return line.substr(first);
      }
    }
  return "unknown";
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

/// This process's command line, each argument quoted for the shell where it
/// needs it (a built-in scene's '?', a space in a file name), so that it
/// pastes back as it ran.
std::string command_line() {
  std::ifstream in("/proc/self/cmdline", std::ios::binary);  // each argument ends with a NUL
  std::string line, arg;
  while (std::getline(in, arg, '\0')) line += (line.empty() ? "" : " ") + shell_quote(arg);
  return line;
}

}  // namespace

double load_average() {
  std::ifstream in("/proc/loadavg");
  double l = -1;
  in >> l;
  return in ? l : -1.0;
}

nlohmann::json program_json() {
  nlohmann::json program = {
      {"version", build_info::kVersion}, {"commit", build_info::kCommit}, {"build_type", build_info::kBuildType}};
#ifdef ACCELVIZ_HAVE_EMBREE
  program["embree"] = std::string(embree_version());
#endif
  program["line"] = version_line();
  return program;
}

nlohmann::json machine_json(unsigned threads_used) {
  return {{"cpu_model", cpu_model()},
          {"hardware_threads", std::thread::hardware_concurrency()},
          {"threads_used", threads_used},
          {"load_average_1min", load_average()},
          {"date", utc_now()},
          {"command_line", command_line()},
          {"program", program_json()}};
}

std::string version_line() {
  std::string line = std::string("accelviz ") + build_info::kVersion + " (commit " + build_info::kCommit + ", " +
                     build_info::kBuildType + " build";
#ifdef ACCELVIZ_HAVE_EMBREE
  line += ", Embree " + std::string(embree_version());
#endif
  return line + ")";
}

void print_json_line(const nlohmann::json& j) {
  write_stdout(json_text(j) + '\n');
}

PngText software_png_text() {
  return {"Software", version_line()};
}

void print_picture_line(nlohmann::json figures) {
  figures["program"] = program_json();
  print_json_line(figures);
}

namespace {
int first_stdout_flush_errno = 0;
}

void flush_stdout() {
  errno = 0;
  if (std::fflush(stdout) != 0 && first_stdout_flush_errno == 0) first_stdout_flush_errno = errno ? errno : EIO;
}

void write_stdout(std::string_view text) {
  errno = 0;
  if (std::fwrite(text.data(), 1, text.size(), stdout) != text.size() && first_stdout_flush_errno == 0)
    first_stdout_flush_errno = errno ? errno : EIO;
  flush_stdout();
}

int stdout_flush_errno() {
  return first_stdout_flush_errno;
}

namespace {

/// ACCELVIZ_PROGRESS_SECONDS when it is a number above 0, else 10.
double progress_line_seconds() {
  const char* text = std::getenv("ACCELVIZ_PROGRESS_SECONDS");
  if (text == nullptr || *text == '\0') return 10.0;
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  return (*end == '\0' && std::isfinite(v) && v > 0.0) ? v : 10.0;
}

}  // namespace

Progress::Progress(bool quiet)
    : quiet_(quiet), tty_(::isatty(STDERR_FILENO) == 1), line_seconds_(progress_line_seconds()) {}

void Progress::begin(const std::string& label) {
  label_ = label;
  last_ = Clock::now();
  if (quiet_) return;
  if (tty_) {
    std::fprintf(stderr, "\r\033[K%s ...", label_.c_str());
    std::fflush(stderr);
  }
}

ProgressCallback Progress::callback() {
  if (quiet_) return {};
  // A terminal: a few updates a second are plenty. Elsewhere (a pipe, a log)
  // whole lines, far apart, so that a long step is not silent until it ends.
  const auto interval = tty_ ? std::chrono::duration<double>(0.2) : std::chrono::duration<double>(line_seconds_);
  return [this, interval](double fraction) {
    // A thread that finds another one printing skips its update rather than wait.
    std::unique_lock lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock()) return true;
    const auto now = Clock::now();
    if (now - last_ < interval) return true;
    last_ = now;
    const double percent = 100.0 * std::clamp(fraction, 0.0, 1.0);
    if (tty_)
      std::fprintf(stderr, "\r\033[K%s %3.0f%%", label_.c_str(), percent);
    else
      std::fprintf(stderr, "%s %.0f%%\n", label_.c_str(), percent);
    std::fflush(stderr);
    return true;
  };
}

void Progress::end(const std::string& result) {
  if (quiet_) return;
  if (tty_) std::fprintf(stderr, "\r\033[K");
  std::fprintf(stderr, "%s%s%s\n", label_.c_str(), result.empty() ? "" : ": ", result.c_str());
  std::fflush(stderr);
}

std::string format_bytes(std::uint64_t bytes) {
  char buf[32];
  if (bytes < 1024) {
    std::snprintf(buf, sizeof buf, "%llu B", static_cast<unsigned long long>(bytes));
  } else if (bytes < 1024ull * 1024) {
    std::snprintf(buf, sizeof buf, "%.1f KiB", static_cast<double>(bytes) / 1024.0);
  } else if (bytes < 1024ull * 1024 * 1024) {
    std::snprintf(buf, sizeof buf, "%.1f MiB", static_cast<double>(bytes) / (1024.0 * 1024.0));
  } else {
    std::snprintf(buf, sizeof buf, "%.2f GiB", static_cast<double>(bytes) / (1024.0 * 1024.0 * 1024.0));
  }
  return buf;
}

void parse_scale_top(const std::string& text, float& value, double& percentile) {
  const bool pct = !text.empty() && (text[0] == 'p' || text[0] == 'P');
  const std::string number = pct ? text.substr(1) : text;
  char* end = nullptr;
  const double v = std::strtod(number.c_str(), &end);
  const bool whole = !number.empty() && end == number.c_str() + number.size() && std::isfinite(v);
  if (pct) {
    if (!whole || !(v > 0.0 && v <= 100.0))
      throw UsageError("--max " + text + ": a percentile is p followed by a number above 0 and at most 100 (p99)");
    percentile = v;
    value = 0.0f;
    return;
  }
  // At least float's smallest normal number: 1e-300 was 0 as a float, and 0 is no top (the scale
  // fell back to the image's maximum under a legend that said "--max 1e-300").
  if (!whole || !(v >= 1.2e-38) || v > 3.4e38)
    throw UsageError("--max " + text +
                     ": expected a number from 1.2e-38 to 3.4e38 (float's range), or pNN for a percentile (p99)");
  value = static_cast<float>(v);
  percentile = 0.0;
}

std::string ordinal(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  std::string s = buf;
  if (v != std::floor(v)) return s + "th";
  const long n = static_cast<long>(v) % 100;
  const char* suffix = (n / 10 == 1) ? "th" : n % 10 == 1 ? "st" : n % 10 == 2 ? "nd" : n % 10 == 3 ? "rd" : "th";
  return s + suffix;
}

std::vector<CommandFactory>& registered_commands() {
  static std::vector<CommandFactory> commands;  // function-local: safe from static initialisation order
  return commands;
}

}  // namespace accelviz::cli
