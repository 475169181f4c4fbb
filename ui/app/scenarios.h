#pragma once
// The lecture's cases as ready setups (the Scenarios menu): each one is a
// built-in scene with one live parameter (the slider), the structures to
// compare on it, a caption saying what to look at, and a measured run:
// every structure is built over the scene and the scene's default view is
// traced (instrumented, small image) for the mean nodes entered, primitive
// tests and cost per ray. GL-free; the GUI runs run_scenario off the main
// thread (ScenarioJob) and shows the figures.
#include <atomic>
#include <cstdint>
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/accel/accel.h"

namespace accelviz {

struct Scenario {
  std::string id;  ///< "teapot-stadium", "walls", ...
  std::string title;
  std::string caption;  ///< what to look at, and which way the figures go
  std::string slider;   ///< what the slider sets
  float min = 0.0f, max = 1.0f, initial = 0.0f;
  bool log_slider = false;              ///< logarithmic slider (ratios, sizes)
  std::vector<std::string> structures;  ///< compared side by side
};

/// Every scenario, in menu order.
const std::vector<Scenario>& scenarios();
/// The scenario with this id, or null.
const Scenario* find_scenario(std::string_view id);
/// The built-in scene spec of a scenario at slider value `value` (clamped to its range).
std::string scenario_scene(const Scenario& s, float value);

struct ScenarioRow {
  std::string structure;
  std::uint64_t triangles = 0;  ///< of the scene (growth: of this run's scene)
  double build_ms = 0.0;
  double sah = 0.0;            ///< BuildStats::sah_cost (0 where the structure has none)
  double nodes_per_ray = 0.0;  ///< mean over the view's rays
  double prims_per_ray = 0.0;
  double cost_per_ray = 0.0;       ///< C_trav·nodes + C_isect·prims with C = 1
  double leaf_volume_ratio = 0.0;  ///< BVH: Σ leaf box volume / root box volume (wasted space of thin walls)
  std::uint32_t max_depth = 0;
};

struct ScenarioFigures {
  std::string id;
  float value = 0.0f;
  std::string scene;              ///< spec (growth: the largest run's)
  std::vector<ScenarioRow> rows;  ///< one per structure (growth: one per structure and N)
  std::string summary;            ///< one line of the measured outcome
};

struct ScenarioRunOptions {
  int width = 64, height = 48;  ///< traced image (the scene's default camera)
  int scene_size = 20000;       ///< `size` of the built-in scene (growth: its largest N)
  unsigned threads = 0;
  const std::atomic<bool>* cancel = nullptr;  ///< set: stop early (throws BuildCancelled)
};

/// Builds and measures. Throws on a bad scene (std::exception with one line).
ScenarioFigures run_scenario(const Scenario& s, float value, const ScenarioRunOptions& opts = {});

/// A run off the main thread: request() starts one (cancelling one in
/// progress), latest() polls.
class ScenarioJob {
 public:
  ~ScenarioJob();
  void request(const Scenario& s, float value, ScenarioRunOptions opts);
  bool busy();
  /// The last finished run's figures (or its one-line error).
  const std::optional<ScenarioFigures>& figures() {
    poll();
    return figures_;
  }
  const std::string& error() {
    poll();
    return error_;
  }

 private:
  void poll();
  std::future<ScenarioFigures> running_;
  std::shared_ptr<std::atomic<bool>> cancel_;
  std::optional<ScenarioFigures> figures_;
  std::string error_;
};

}  // namespace accelviz
