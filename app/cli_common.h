#pragma once
// What the subcommands share: option groups, parsing of small values, output
// file rules, progress on stderr, timing. Thin: the work happens in core/.
#include <CLI/CLI.hpp>
#include <chrono>
#include <filesystem>
#include <functional>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "core/accel/factory.h"
#include "core/geometry/triangle.h"
#include "core/scene/scene.h"
#include "core/util/image_size.h"
#include "core/util/one_line.h"  // count_of: "1 thread", "2 threads"
#include "core/util/output_file.h"
#include "core/util/timing.h"

namespace accelviz {
struct SweepResult;  // core/analysis/sweep.h
struct LabResult;    // core/analysis/robustness_lab.h
struct FrameStats;   // core/scene/animation.h
struct PngText;      // core/analysis/heatmap.h
}

namespace accelviz::cli {

/// A registered subcommand: its CLI11 app and what runs it once parsed.
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

/// Options every subcommand sees.
struct GlobalOptions {
  bool quiet = false;  ///< no progress on stderr
};

Command add_info_command(CLI::App& parent, const GlobalOptions& global);
Command add_render_command(CLI::App& parent, const GlobalOptions& global);
Command add_bench_command(CLI::App& parent, const GlobalOptions& global);
Command add_trace_command(CLI::App& parent, const GlobalOptions& global);
Command add_rays_command(CLI::App& parent, const GlobalOptions& global);
/// `accelviz` without a subcommand and no display: the demo heatmap as a PNG.
int run_demo(const GlobalOptions& global);

/// Further subcommands register themselves from their own file, so adding
/// one never touches main.cpp:
///   static const CommandRegistration reg{add_sweep_command};
/// main() adds them after the built-in ones, in registration order.
using CommandFactory = Command (*)(CLI::App& parent, const GlobalOptions& global);
std::vector<CommandFactory>& registered_commands();
struct CommandRegistration {
  explicit CommandRegistration(CommandFactory factory) { registered_commands().push_back(factory); }
};

/// A semantic usage problem found after parsing (exit code 2, like CLI11's own).
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// ---- values ------------------------------------------------------------------

/// --max's text: a finite value > 0 (into `value`) or "pNN" with 0 < NN <= 100 (into `percentile`); a
/// UsageError naming the text otherwise.
void parse_scale_top(const std::string& text, float& value, double& percentile);
/// "99th", "1st", "22nd", "99.5th": a percentile's rank in words.
std::string ordinal(double v);

/// parse_image_size (core/util/image_size.h), or a UsageError naming the text.
ImageSize parse_size(const std::string& text);
/// CLI11 validator for parse_size.
CLI::Validator size_validator();

// ---- option groups -------------------------------------------------------------

/// --structure options shared by render, bench, trace and rays.
struct StructureCli {
  std::string splitter = "binned";
  int buckets = BvhOptions{}.buckets;
  int leaf = BvhOptions{}.max_leaf_size;
  int leaf_cap = BvhOptions{}.leaf_size_cap;
  bool leaf_cap_given = false;  ///< --leaf-cap on the command line (or leaf-cap in --compare)
  int wide = BvhOptions{}.wide_width;
  float ctrav = BvhOptions{}.cost_traversal;
  float cisect = BvhOptions{}.cost_intersect;
  std::string embree_quality = "medium";
  bool embree_robust = false;
  std::string embree_isa = "auto";

  /// Adds the options to `app`; without `with_embree` (a command that builds BVHs only) no --embree-*.
  void add_to(CLI::App* app, bool with_embree = true);
  /// The options given on the command line that none of `structures` uses, as one line ("" when
  /// there are none): "grid does not use --leaf, --ctrav (...)". The BVH's options act on bvh and
  /// tlas (--ctrav and --cisect also on any structure's `cost` metric, `cost_metric`), --embree-* on
  /// embree. A knob turned on a structure that ignores it changed nothing, without a word.
  std::string unused_note(const std::vector<std::string>& structures, bool cost_metric) const;
  /// unused_note's line on stderr as "accelviz: note: ...", unless `quiet`.
  void say_unused(const std::vector<std::string>& structures, bool cost_metric, bool quiet) const;
  /// Options for the factory; `threads` is the build thread count. The leaf
  /// cap is raised to --leaf where it was not given; a --leaf-cap given below
  /// --leaf is a UsageError (it was ignored in silence).
  StructureOptions to_options(unsigned threads, bool compute_epo) const;

 private:
  std::vector<const CLI::Option*> bvh_options_;     ///< --splitter ... --wide, as added
  std::vector<const CLI::Option*> embree_options_;  ///< --embree-*, as added
};

/// camera_from_spec with a bad spec reported as a usage error. A scene no
/// framing camera can see (near the float range) is a runtime error that
/// points at --camera where the command has one.
Camera camera_for(const std::string& spec, const Scene& scene, const ImageSize& size, bool has_camera_option = true);

/// Adds --triangle-test (watertight | fast, the names parse_triangle_test
/// reads) to `sub`, stored in `value`; `help` replaces the usual help text.
CLI::Option* add_triangle_test_option(CLI::App* sub, std::string& value, const char* help = nullptr);

/// Most threads a command takes: more than any machine has cores, few
/// enough that creating them cannot exhaust the process's limits (100,000
/// threads could fail to start, or crash, instead of running).
inline constexpr unsigned kMaxThreads = 1024;

/// CLI11 checks for floating-point options: a finite number > 0, a finite
/// number in [lo, hi]. (CLI::PositiveNumber and CLI::Range let nan and inf
/// through, and word the positive range as "0.000000 to 1797693...".)
CLI::Validator finite_positive();
CLI::Validator finite_range(double lo, double hi);
/// A C_trav or C_isect: from 1e-6 to 1e6 (cost_constant_problem), as the GUI's fields, --compare and sweep.
CLI::Validator cost_constant();

/// `--threads,-j N` (0: all hardware threads), checked to 0..kMaxThreads.
CLI::Option* add_threads_option(CLI::App* sub, unsigned& value, const char* help);
/// --triangle-test watertight|fast.
TriangleTest parse_triangle_test(const std::string& name);

// ---- scenes, files, output -------------------------------------------------------

/// load_scene, then a note on stderr when the loader reported warnings.
Scene load_scene_noting_warnings(const std::string& spec, bool quiet);
/// Throws (one line, exit 1) when `scene` is instanced and was left
/// unflattened (too large: only the two-level structure holds it): `command`
/// measures the flattened triangle list, which that scene does not have.
void require_flattened(const Scene& scene, const std::string& spec, const char* command);

/// Fails early (before any long work) when `path` exists and `force` is off,
/// or its directory does not exist: "<path>: exists (use --force to overwrite)".
void check_output_path(const std::string& path, bool force);

/// The files a command writes into its output folder (sweep, refit): what
/// messages call them ("sweep files") and every name any of its runs can
/// write, built by its naming scheme. Only these names are refused, replaced
/// or removed: a file of the user's own in the folder is never touched.
struct OutputDirFiles {
  std::string label;
  std::vector<std::string> names;
};

/// Before any work: refused (one line) when `dir` is not a folder, cannot be
/// written in, or holds one of the files and `force` is off ("DIR: already
/// holds sweep files (use --force to overwrite)"); nothing changes on disk.
void check_output_dir(const std::string& dir, const OutputDirFiles& files, bool force);

/// Once the results are ready: the folder's files, written all or nothing
/// (core's OutputFolder). The constructor checks the folder again (it may
/// have changed during the work) and creates it where missing; add() writes
/// each file to a temporary in the folder; commit() gives them their names
/// only once all were written, then removes the files of an earlier run that
/// this one did not write (stale charts would mislead). A run that fails
/// (throws, std::runtime_error "<path>: <problem>") leaves the folder as it
/// was: the old results, no temporary, and no folder it created.
class OutputDirWriter {
 public:
  OutputDirWriter(const std::string& dir, const OutputDirFiles& files, bool force);
  void add(const std::string& name, const std::string& bytes);
  void commit();

 private:
  std::string label_;
  OutputFolder folder_;
};

/// Writes several files (render -s a,b's images, --compare's trio) all or
/// nothing (core's write_output_files): all temporaries first, then the
/// names. Throws std::runtime_error "<path>: exists (use --force to
/// overwrite)" or "<path>: <problem>"; then no file has changed.
void write_output_set(const std::vector<OutputBytes>& files, bool force);

/// `x` as printf's %g writes it ("1e+06", "0.02"), for messages.
std::string number_text(double x);

/// Absolute, normalised form of a path for messages.
std::string absolute_path(const std::string& path);

/// `path` as a line of stdout: each control byte (a newline, an ESC) shown as
/// '?', so that the line stays one line a script can read (the JSON that
/// follows holds the name exactly).
std::string path_line(const std::string& path);

/// The items of a comma-separated option value, empty ones included ("a,,b" has three: an empty
/// item is a typo to refuse, which CLI11's own list splitting drops in silence).
std::vector<std::string> comma_items(const std::string& text);
/// "{a,b,c}", as CLI11 lists the values an option takes.
std::string braced_names(const std::vector<std::string>& names);
/// "" or what is wrong with a comma-separated list of `names` (a CLI11 validator's answer): an
/// empty item, a name not among them, or one listed twice.
std::string name_list_problem(const std::string& text, const std::vector<std::string>& names);

/// The 1-minute load average of /proc/loadavg (-1 where it cannot be read).
double load_average();

/// Where and with what a measurement ran, recorded in the JSON of bench,
/// sweep and calibrate: the CPU model, hardware threads, `threads_used`, the
/// load average, the UTC date, this command line, and program_json().
nlohmann::json machine_json(unsigned threads_used);

/// "accelviz 0.1.0 (commit 9627f3c8f5bd, Release build, Embree 3.13.5)": --version's line.
std::string version_line();

/// The build that made an output, one shape in every JSON that names it (bench,
/// sweep and calibrate's `machine`, render's and the demo's line, screenshot
/// side-cars): {version, commit, build_type, embree (where built with it),
/// line: version_line()}.
nlohmann::json program_json();

/// One setting's figures as sweep.json's `results` hold them (`budget`: the
/// ray budget of trace_ms_budget and total_ms_budget); the GUI's dump-sweep too.
nlohmann::json sweep_result_json(const SweepResult& r, double budget);

/// The robustness lab's figures as `robustness --json` prints them (triangles, rays,
/// rays_by_family, reference_hits, reference_ms, variants); the GUI's dump-robustness too.
nlohmann::json lab_result_json(const LabResult& r);

/// One animated frame's figures as `animate --json` prints them (frame, time, moved_instances,
/// refits, rebuilds, tlas_rebuilt, tlas_rebuild_ms, refit_ms, rebuild_ms, sah_refit, sah_rebuilt,
/// overlap_area, overlap_volume, overlap_pairs); the GUI's dump-dynamics history too.
nlohmann::json frame_stats_json(const FrameStats& f);

/// One-line JSON on stdout, flushed (animate streams a line per frame).
void print_json_line(const nlohmann::json& j);

/// The PNG text naming the build that drew a picture: {"Software", version_line()}.
PngText software_png_text();

/// print_json_line of a picture's figures with the `program` that drew it.
void print_picture_line(nlohmann::json figures);

/// Flushes stdout and remembers the reason of the first failed flush: glibc
/// drops the buffer after a failed write, so that main's final flush succeeds
/// with nothing to write and the reason (a full disk) would be lost.
void flush_stdout();

/// Writes TEXT to stdout and flushes it, keeping a failed write's reason as
/// flush_stdout does (a text longer than stdout's buffer fails inside the write).
void write_stdout(std::string_view text);

/// errno of the first failed flush_stdout() or write_stdout(), 0 if none failed.
int stdout_flush_errno();

// ---- progress and timing -----------------------------------------------------------

/// Progress on stderr: on a terminal, one line updated in place; otherwise
/// (a pipe, a log file) one line per finished step, and for a step that runs
/// long a "LABEL NN%" line every ACCELVIZ_PROGRESS_SECONDS seconds (default
/// 10). Silent when quiet.
class Progress {
 public:
  explicit Progress(bool quiet);
  void begin(const std::string& label);
  /// A ProgressCallback for builders and batches (never cancels).
  ProgressCallback callback();
  void end(const std::string& result = {});
  bool quiet() const { return quiet_; }

 private:
  bool quiet_;
  bool tty_;
  double line_seconds_;  ///< not a terminal: seconds between "LABEL NN%" lines
  std::string label_;
  std::chrono::steady_clock::time_point last_;
  std::mutex mutex_;  ///< builders may report from several threads
};

/// load_scene_noting_warnings between progress lines ("loading SPEC", then
/// its triangle count).
Scene load_scene_with_progress(const std::string& spec, bool quiet, Progress& progress);

/// Builds `structure` over the scene's triangles between progress lines
/// ("building LABEL", LABEL the structure's name when empty; then its build
/// ms). "tlas" takes its two levels from the scene's meshes and instances
/// (so.scene is set to `scene`, which must outlive the structure).
/// Also notes on stderr (unless quiet) where the level of `structure`
/// differs from what the scene calls for (level_note).
std::unique_ptr<Accelerator> build_with_progress(const std::string& structure, const Scene& scene, StructureOptions so,
                                                 Progress& progress, const std::string& label = {});

/// "" or a note that `structure` is not the level the scene's effects call
/// for: a single-level structure over a scene that instances a mesh more
/// than once ("...: `-s tlas` builds the two-level structure it calls for;
/// bvh flattens its instances"), or tlas over one that does not.
std::string level_note(const Scene& scene, const std::string& structure);

using Clock = std::chrono::steady_clock;

/// "12.3 MiB", "512 B" for humans.
std::string format_bytes(std::uint64_t bytes);

}  // namespace accelviz::cli
