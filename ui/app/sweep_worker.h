#pragma once
// The "Cost of accuracy" panel's engine, GL-free: the same parameter sweep
// as `accelviz sweep` (core/analysis/sweep.h) run on the current scene on a
// worker thread, publishing a snapshot after every setting so the charts
// grow live; optionally the calibration of `accelviz calibrate` and the BVH
// built with default vs calibrated SAH constants. A new request supersedes
// the one running (cancelled between or inside settings, like the build and
// heatmap workers); cancel() stops it and keeps what was measured.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/analysis/calibrate.h"
#include "core/analysis/sweep.h"
#include "core/query/camera.h"
#include "ui/app/app_config.h"
#include "ui/app/build_worker.h"
#include "ui/app/latest_job_worker.h"

namespace accelviz {

/// "buckets=2,4,8 leaf=1,4" (pairs separated by spaces or ';') → params.
/// Throws std::invalid_argument with the sweep's one-line message (unknown
/// parameter for `structure`, bad value, parameter given twice, nothing given).
std::vector<SweepParam> parse_sweep_params_text(std::string_view structure, std::string_view text);

/// A small default sweep of the structure's main quality knob, e.g.
/// "buckets=2,4,8,16,32,exact" for bvh, "lambda=0.5,1,2,4,8" for grid.
std::string default_sweep_params_text(std::string_view structure);

/// Writes a measured setting into the app's structure choice (name and
/// options; `triangle` goes to the query options). "" or a one-line error;
/// `choice` is unchanged on error.
std::string apply_sweep_point(StructureChoice& choice, std::string_view structure, const SweepSetting& setting);

/// The swept figures the panel can chart against a parameter.
enum class SweepFigure { sah_cost, rays_per_s, nodes_per_ray, prims_per_ray, build_ms, total_ms, memory, edge_misses };
inline constexpr int kSweepFigureCount = 8;
const char* sweep_figure_name(SweepFigure f);
/// The figure's value for `r` (total_ms for `rays` rays).
double sweep_figure_value(const SweepResult& r, SweepFigure f, double rays);

/// One line of a "figure vs parameter" chart: the results that share every
/// other parameter's value, ordered by the swept parameter's value index.
struct SweepSeries {
  std::string label;                ///< the other parameters' values ("leaf=4"), "" when only one parameter
  std::vector<int> value_index;     ///< index into the parameter's value list, per point
  std::vector<std::size_t> result;  ///< index into the results, per point
};
/// Groups `results` for parameter `param` (position in each setting).
std::vector<SweepSeries> sweep_series(std::span<const SweepResult> results, std::size_t param);

struct SweepRequest {
  std::shared_ptr<const LoadedScene> scene;  ///< kept alive while the sweep runs
  std::string structure = "bvh";
  StructureOptions base;  ///< options before each setting (the Structure panel's)
  QueryOptions query;
  std::vector<SweepParam> params;  ///< may be empty (one setting: `base`)
  Camera camera;                   ///< primary rays of this view
  int width = 160, height = 120;
  int repeat = 1;
  unsigned threads = 0;
  std::size_t edge_probes = 2000;  ///< when `triangle` is swept
  std::uint64_t seed = 1;
  bool calibrate = false;  ///< also calibrate and compare the BVH's constants
  CalibrateOptions calibrate_options{1 << 16, 1 << 21, 3, 1};
};

struct SweepSnapshot {
  enum class State { running, done, cancelled, failed };
  std::uint64_t id = 0;
  State state = State::running;
  std::string structure;
  std::vector<SweepParam> params;
  std::vector<SweepSetting> settings;
  std::vector<SweepResult> results;  ///< measured so far, in settings order
  std::size_t rays = 0, probes = 0, triangles = 0;
  std::string stage;  ///< what runs now ("bvh buckets=8", "calibrating")
  std::string error;  ///< when failed: one line
  std::optional<CalibrationReport> calibration;
  /// How far the setting being measured is (0..1): its builds report inside,
  /// so that one slow build (a deep octree) does not stall the bar.
  double setting_fraction = 0;

  /// (settings measured + setting_fraction) / settings (the calibration counts as one)
  double fraction() const;
};

/// Runs request `r` synchronously, publishing a snapshot after each step;
/// returns the last one. `keep_going` is asked often (any thread). The
/// worker's engine, exposed for tests.
std::shared_ptr<const SweepSnapshot> run_sweep_request(
    const SweepRequest& r, std::uint64_t id, const std::function<bool()>& keep_going,
    const std::function<void(std::shared_ptr<const SweepSnapshot>)>& publish);

class SweepWorker {
 public:
  SweepWorker();
  ~SweepWorker() = default;  ///< cancels and joins
  SweepWorker(const SweepWorker&) = delete;
  SweepWorker& operator=(const SweepWorker&) = delete;

  /// Replaces whatever is queued or running with `r`; returns its id.
  std::uint64_t request(SweepRequest r) { return worker_.request(std::move(r)); }
  /// Stops the running sweep (its snapshot turns `cancelled`, results kept) and drops the queued one.
  void cancel() { worker_.cancel(); }
  /// The newest snapshot of the newest job that published (null before the first).
  std::shared_ptr<const SweepSnapshot> latest() const { return worker_.latest(); }
  bool busy() const { return worker_.busy(); }

 private:
  LatestJobWorker<SweepRequest, std::shared_ptr<const SweepSnapshot>> worker_;
};

}  // namespace accelviz
