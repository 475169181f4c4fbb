// The GUI's heatmap with the "instances visited" metric: the progressive
// worker's pixels and summary carry the two-level count, the option parses.
#include <gtest/gtest.h>

#include "core/accel/factory.h"
#include "core/accel/tlas/tlas.h"
#include "core/query/camera.h"
#include "core/scene/load.h"
#include "ui/app/app_config.h"
#include "ui/app/heatmap_worker.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_app_instances_metric {

using namespace accelviz;

std::shared_ptr<const BuiltStructure> forest_built(const std::string& structure) {
  auto scene = std::make_shared<LoadedScene>();
  scene->spec = "builtin:forest?size=2000&seed=3";
  scene->scene = load_scene(scene->spec);
  StructureOptions so;
  so.scene = &scene->scene;
  auto built = std::make_shared<BuiltStructure>();
  built->accel = build_accelerator(structure, scene->scene.triangles, so);
  built->scene = scene;
  return built;
}

TEST(AppInstancesMetric, WorkerPixelsAndSummaryCountInstances) {
  AppConfig c;
  ASSERT_EQ(apply_option(c, "metric", "instances"), "");
  EXPECT_EQ(c.view.metric, HeatMetric::instances);
  EXPECT_EQ(option_value(c, "metric"), "instances");

  for (const std::string structure : {"tlas", "bvh"}) {
    const auto built = forest_built(structure);
    HeatmapRequest r;
    r.structure = built;
    r.options.width = 40;
    r.options.height = 30;
    r.camera = camera_from_spec("", built->scene->scene, 40.0f / 30.0f);
    r.options.metric = c.view.metric;
    r.options.threads = 2;
    std::shared_ptr<const HeatmapFrame> last;
    ASSERT_TRUE(trace_progressive(
        r, 1, [] { return true; }, [&](auto f) { last = f; }));
    ASSERT_TRUE(last && last->complete);
    const Tlas* tlas = dynamic_cast<const Tlas*>(built->accel.get());
    ASSERT_EQ(tlas != nullptr, structure == "tlas");
    double sum = 0.0;
    std::uint32_t max = 0;
    for (int y = 0; y < r.options.height; ++y)
      for (int x = 0; x < r.options.width; ++x) {
        const PixelFigures& p = last->at(x, y);
        EXPECT_EQ(p.value, static_cast<float>(p.instances));
        if (tlas) {
          TwoLevelRayStats ts;
          tlas->closest_hit_two_level(primary_ray(r.camera, x, y, r.options.width, r.options.height), r.options.query,
                                      &ts);
          ASSERT_EQ(p.instances, ts.instances_visited) << structure << " pixel " << x << "," << y;
        } else {
          ASSERT_EQ(p.instances, 0u);
        }
        sum += p.instances;
        max = std::max(max, p.instances);
      }
    EXPECT_NEAR(last->summary.mean_instances, sum / (r.options.width * r.options.height), 1e-9);
    EXPECT_EQ(last->summary.max_instances, max);
    if (tlas) {
      EXPECT_GT(last->summary.mean_instances, 0.5);
      EXPECT_GE(max, 2u);
    } else {
      EXPECT_EQ(max, 0u);
    }
  }
}

}  // namespace unity_test_app_instances_metric
