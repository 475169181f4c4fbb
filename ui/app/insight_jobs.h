#pragma once
// The insight views' background work, GL-free: the A/B comparison (build A
// and B over the shown scene, render both on the current view, difference
// them) and the view insight of the structure shown (every ray's visits
// recorded: hot nodes, predicted vs measured cost, the traversal modes).
// Each runs on its own thread; a new request cancels the one in progress.
#include <atomic>
#include <functional>
#include <future>
#include <memory>
#include <optional>
#include <string>

#include "core/analysis/insight/compare_images.h"
#include "core/analysis/insight/predicted_cost.h"
#include "core/analysis/insight/traversal_modes.h"
#include "core/analysis/insight/visit_attribution.h"
#include "ui/app/build_worker.h"

namespace accelviz {

/// One background computation at a time; request() cancels the previous one
/// (its function sees `cancel` set and should throw BuildCancelled).
template <typename T>
class AsyncJob {
 public:
  using Fn = std::function<T(const std::atomic<bool>& cancel)>;
  ~AsyncJob() { stop(); }
  void request(Fn fn) {
    stop();
    cancel_ = std::make_shared<std::atomic<bool>>(false);
    running_ = std::async(std::launch::async, [fn = std::move(fn), c = cancel_] { return fn(*c); });
  }
  bool busy() {
    poll();
    return running_.valid();
  }
  const std::shared_ptr<const T>& result() {
    poll();
    return result_;
  }
  const std::string& error() {
    poll();
    return error_;
  }

 private:
  void stop() {
    if (cancel_) cancel_->store(true);
    if (running_.valid()) {
      running_.wait();
      try {
        running_.get();
      } catch (...) {
      }
    }
  }
  void poll() {
    if (!running_.valid() || running_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
    try {
      result_ = std::make_shared<const T>(running_.get());
      error_.clear();
    } catch (const BuildCancelled&) {
    } catch (const std::exception& e) {
      error_ = e.what();
    }
  }
  std::future<T> running_;
  std::shared_ptr<std::atomic<bool>> cancel_;
  std::shared_ptr<const T> result_;
  std::string error_;
};

// ---- A/B ----------------------------------------------------------------------

struct ABRequest {
  std::shared_ptr<const LoadedScene> scene;
  StructureChoice a, b;
  Camera camera;
  int width = 160, height = 120;
  HeatMetric metric = HeatMetric::nodes;
  unsigned threads = 0;
};

struct ABResult {
  StructureChoice a, b;
  MetricImage image_a, image_b, diff;
  ABFigures figures;
  float locked_max = 1.0f;  ///< one colour scale for A and B
  float diff_scale = 1.0f;  ///< symmetric scale of the difference
  double build_ms_a = 0.0, build_ms_b = 0.0;
  double sah_a = 0.0, sah_b = 0.0;            ///< 0 where a structure has no SAH (grid, voxels, embree)
  double trace_ms_a = 0.0, trace_ms_b = 0.0;  ///< the view's closest hits without counters (median of 3)
  std::uint64_t hits_a = 0, hits_b = 0;       ///< rays that hit something
  std::uint64_t hits_changed = 0;             ///< rays whose hit differs (hit vs miss, or another triangle)
  std::string uncounted;  ///< a side that counts nothing per ray (embree): its images are 0, no count compares
};

/// Builds both sides and renders them (throws BuildCancelled when `cancel` is set).
ABResult run_ab(const ABRequest& r, const std::atomic<bool>& cancel);

/// "bvh binned B=16 leaf 4", one line to label a side.
std::string describe_choice(const StructureChoice& c);

// ---- the view's insight -----------------------------------------------------------

struct ViewInsightRequest {
  std::shared_ptr<const BuiltStructure> built;
  Camera camera;
  int width = 128, height = 96;
  unsigned threads = 0;
};

struct ViewInsight {
  std::shared_ptr<const BuiltStructure> built;  ///< what it was measured on
  VisitRecord record;
  std::vector<std::uint64_t> visits;  ///< per node
  std::vector<HotNode> hot;           ///< top 20
  bool is_bvh = false;
  CostComparison cost;            ///< BVH only
  std::vector<double> predicted;  ///< BVH: A(n)/A(root)
  std::vector<double> measured;   ///< BVH: fraction of root rays entering n
  std::vector<ModeTotals> modes;  ///< one per kTraversalModes
};

ViewInsight run_view_insight(const ViewInsightRequest& r, const std::atomic<bool>& cancel);

}  // namespace accelviz
