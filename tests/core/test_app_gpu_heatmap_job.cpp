// AppState's side of the GPU heatmap (ui/app/gpu_heatmap_job.h), GL-free:
// a fake job that "traces" 8 rows per step shows that AppState steps the job
// once per update with the heatmap-gpu-ms budget, keeps the previous heatmap
// up until the job's frame is complete, reports progress, restarts the job
// when the view changes mid-trace, and falls back to the CPU worker (with
// the reason) when the job fails mid-trace.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <thread>

#include "core/scene/load.h"
#include "ui/app/app_state.h"
#include "ui/app/gpu_heatmap_job.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_app_gpu_heatmap_job {

using namespace accelviz;

class FakeGpuJob final : public GpuHeatmapJob {
 public:
  void start(const HeatmapRequest& r, std::uint64_t id) override {
    request = r;
    id_ = id;
    running_ = true;
    progress_ = {};
    progress_.rows = r.options.height;
    ++starts;
  }
  std::shared_ptr<const HeatmapFrame> step(double budget_ms) override {
    budgets.push_back(budget_ms);
    if (fail_at_band >= 0 && progress_.bands == fail_at_band) {
      running_ = false;
      throw std::runtime_error("fake GL trouble");
    }
    progress_.rows_done = std::min(progress_.rows, progress_.rows_done + 8);
    ++progress_.bands;
    if (progress_.rows_done < progress_.rows) return nullptr;
    running_ = false;
    auto f = std::make_shared<HeatmapFrame>();
    f->id = id_;
    f->stride = 1;
    f->complete = true;
    f->request = request;
    f->image.width = request.options.width;
    f->image.height = request.options.height;
    f->image.values.assign(static_cast<std::size_t>(request.options.width) * request.options.height, 1.0f);
    f->pixels.resize(f->image.values.size());
    return f;
  }
  void cancel() override {
    if (running_) ++cancels;
    running_ = false;
  }
  bool busy() const override { return running_; }
  Progress progress() const override { return progress_; }

  HeatmapRequest request;
  int starts = 0, cancels = 0;
  int fail_at_band = -1;
  std::vector<double> budgets;

 private:
  std::uint64_t id_ = 0;
  bool running_ = false;
  Progress progress_;
};

constexpr int kW = 64, kH = 48;  // 6 bands of 8 rows

// Updates until the structure is shown (the build runs on a worker thread).
void gpu_job_wait_built(AppState& app) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!app.current() && std::chrono::steady_clock::now() < deadline) {
    app.update(kW, kH);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_TRUE(app.current()) << app.error();
}

AppSettings gpu_job_settings() {
  AppSettings s;
  s.config.view.heatmap_gpu = true;
  s.config.view.heatmap_gpu_ms = 5.0f;
  return s;
}

TEST(AppGpuHeatmapJob, SteppedOncePerUpdateAndShownOnlyWhenComplete) {
  FakeGpuJob job;
  AppState app(gpu_job_settings());
  app.set_gpu_heatmap_tracer(&job);
  app.open_scene("builtin:teapot?size=200");
  gpu_job_wait_built(app);  // the update that shows the structure starts the job and steps it once
  ASSERT_EQ(job.starts, 1);
  EXPECT_EQ(job.request.options.width, kW);
  EXPECT_EQ(job.request.options.height, kH);
  EXPECT_TRUE(job.request.shadow_lights.empty());
  for (int band = 1; band < 6; ++band) {
    ASSERT_TRUE(app.gpu_heatmap_progress());
    EXPECT_EQ(app.gpu_heatmap_progress()->rows_done, 8 * band);
    EXPECT_EQ(app.gpu_heatmap_progress()->rows, kH);
    EXPECT_TRUE(app.heatmap_busy());
    EXPECT_FALSE(app.settled());
    EXPECT_FALSE(app.heatmap_on_gpu());  // nothing of the GPU's shown mid-trace
    EXPECT_EQ(app.stats_json()["gpu_trace"]["rows_done"], 8 * band);
    const AppState::FrameUpdate u = app.update(kW, kH);
    EXPECT_EQ(u.heatmap_changed, band == 5) << band;
  }
  EXPECT_EQ(job.starts, 1);
  ASSERT_EQ(job.budgets.size(), 6u);
  for (const double b : job.budgets) {  // heatmap-gpu-ms, or the rest of the last frame (at most 100 ms)
    EXPECT_GE(b, 5.0);
    EXPECT_LE(b, 100.0);
  }
  EXPECT_FALSE(app.gpu_heatmap_progress());
  EXPECT_TRUE(app.heatmap_on_gpu());
  ASSERT_TRUE(app.heatmap());
  EXPECT_TRUE(app.heatmap()->complete);
  EXPECT_TRUE(app.settled());
  EXPECT_TRUE(app.stats_json()["gpu_trace"].is_null());
  EXPECT_EQ(app.stats_json()["view"]["device"], "gpu");
  EXPECT_FALSE(app.heatmap_busy());
  app.update(kW, kH);  // nothing changed: no new trace
  EXPECT_EQ(job.starts, 1);
  app.set_gpu_heatmap_tracer(nullptr);
}

TEST(AppGpuHeatmapJob, ANewViewMidTraceRestartsTheJob) {
  FakeGpuJob job;
  AppState app(gpu_job_settings());
  app.set_gpu_heatmap_tracer(&job);
  app.open_scene("builtin:teapot?size=200");
  gpu_job_wait_built(app);
  app.update(kW, kH);
  ASSERT_EQ(app.gpu_heatmap_progress()->rows_done, 16);
  const glm::vec3 before = job.request.camera.position;
  app.set_camera_spec("0,0,6,0,0,0,40");
  app.update(kW, kH);
  EXPECT_EQ(job.starts, 2);
  EXPECT_EQ(job.cancels, 1);
  EXPECT_NE(job.request.camera.position, before);
  EXPECT_EQ(app.gpu_heatmap_progress()->rows_done, 8);  // the new view's first band
  ASSERT_EQ(app.set_option("metric", "prims"), "");
  app.update(kW, kH);
  EXPECT_EQ(job.starts, 3);
  EXPECT_EQ(job.request.options.metric, HeatMetric::prims);
  // Trace on the CPU again: the job is dropped, the worker traces.
  ASSERT_EQ(app.set_option("heatmap-gpu", "off"), "");
  app.update(kW, kH);
  EXPECT_EQ(job.cancels, 3);
  EXPECT_FALSE(app.gpu_heatmap_progress());
  app.set_gpu_heatmap_tracer(nullptr);
}

TEST(AppGpuHeatmapJob, AFailureMidTraceFallsBackToTheCpu) {
  FakeGpuJob job;
  job.fail_at_band = 2;
  AppState app(gpu_job_settings());
  app.set_gpu_heatmap_tracer(&job);
  app.open_scene("builtin:teapot?size=200");
  gpu_job_wait_built(app);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!app.settled() && std::chrono::steady_clock::now() < deadline) {
    app.update(kW, kH);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_TRUE(app.settled());
  EXPECT_EQ(app.gpu_heatmap_note(), "fake GL trouble");
  EXPECT_FALSE(app.heatmap_on_gpu());
  ASSERT_TRUE(app.heatmap());
  EXPECT_TRUE(app.heatmap()->complete);
  EXPECT_EQ(app.heatmap()->summary.rays, static_cast<std::uint64_t>(kW) * kH);  // the CPU's frame
  EXPECT_EQ(app.stats_json()["view"]["device"], "cpu");
  EXPECT_EQ(job.starts, 1);
  app.set_gpu_heatmap_tracer(nullptr);
}

TEST(AppGpuHeatmapJob, BudgetIsTheSettingOrTheRestOfTheLastFrameCapped) {
  // No previous frame, or a setting of 0 ("one band a frame"): the setting.
  EXPECT_EQ(gpu_heatmap_budget_ms(5.0, 0.0, 0.0), 5.0);
  EXPECT_EQ(gpu_heatmap_budget_ms(0.0, 40.0, 2.0), 0.0);
  // A fast frame: the setting stays the larger.
  EXPECT_EQ(gpu_heatmap_budget_ms(5.0, 6.0, 3.0), 5.0);
  // A slow frame (llvmpipe): the rest of it, without its GPU step.
  EXPECT_EQ(gpu_heatmap_budget_ms(5.0, 40.0, 10.0), 30.0);
  // ...capped at 100 ms.
  EXPECT_EQ(gpu_heatmap_budget_ms(5.0, 400.0, 10.0), 100.0);
  // A frame that was all GPU step leaves the setting.
  EXPECT_EQ(gpu_heatmap_budget_ms(5.0, 10.0, 12.0), 5.0);
}

}  // namespace unity_test_app_gpu_heatmap_job
