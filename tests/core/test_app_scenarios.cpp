// Insight scenarios (ui/app/scenarios.h): every case runs at a small size
// and its figures move the way its caption says; the script commands that
// drive them parse and reject bad input.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "ui/app/scenarios.h"
#include "ui/app/script.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_app_scenarios {

using namespace accelviz;

namespace {

ScenarioRunOptions small() {
  ScenarioRunOptions o;
  o.width = 40;
  o.height = 30;
  o.scene_size = 3000;
  return o;
}

const ScenarioRow& row(const ScenarioFigures& f, const std::string& structure) {
  for (const ScenarioRow& r : f.rows)
    if (r.structure == structure) return r;
  throw std::runtime_error("no row " + structure);
}

}  // namespace

TEST(AppScenarios, EveryScenarioRunsWithFiniteFigures) {
  for (const Scenario& s : scenarios()) {
    EXPECT_FALSE(s.caption.empty()) << s.id;
    EXPECT_EQ(find_scenario(s.id), &s);
    ScenarioRunOptions o = small();
    const float value = s.id == "growth" ? 2000.0f : s.min;  // the cheapest end (growth: below its range, clamped)
    const ScenarioFigures f = run_scenario(s, value, o);
    EXPECT_GE(f.value, s.min);
    EXPECT_LE(f.value, s.max);
    ASSERT_FALSE(f.rows.empty()) << s.id;
    for (const ScenarioRow& r : f.rows) {
      EXPECT_GT(r.triangles, 0u) << s.id;
      EXPECT_TRUE(std::isfinite(r.cost_per_ray)) << s.id << " " << r.structure;
      EXPECT_GE(r.cost_per_ray, 0.0);
    }
  }
  EXPECT_EQ(find_scenario("nope"), nullptr);
}

TEST(AppScenarios, RotatedWallsCostMoreThanAligned) {
  const Scenario& walls = *find_scenario("walls");
  const ScenarioFigures aligned = run_scenario(walls, 0.0f, small());
  const ScenarioFigures rotated = run_scenario(walls, 45.0f, small());
  EXPECT_GT(row(rotated, "bvh").leaf_volume_ratio, 2.0 * row(aligned, "bvh").leaf_volume_ratio);
  EXPECT_GT(row(rotated, "bvh").cost_per_ray, row(aligned, "bvh").cost_per_ray);
}

TEST(AppScenarios, GrowthPlotsFourSizesPerStructure) {
  const ScenarioFigures g = run_scenario(*find_scenario("growth"), 4000.0f, small());
  ASSERT_EQ(g.rows.size(), 8u);  // N/64, N/16, N/4, N for grid and bvh
  EXPECT_LT(g.rows.front().triangles, g.rows.back().triangles);
  EXPECT_NE(g.summary.find("bvh nodes/ray"), std::string::npos);
}

TEST(AppScenarios, JobRunsInTheBackground) {
  ScenarioJob job;
  job.request(*find_scenario("same-centroid"), 200.0f, small());
  const auto t0 = std::chrono::steady_clock::now();
  while (job.busy() && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(60))
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_TRUE(job.figures().has_value()) << job.error();
  EXPECT_EQ(job.figures()->id, "same-centroid");
  EXPECT_EQ(job.figures()->rows.size(), 2u);
}

TEST(AppScenarios, ScriptCommands) {
  const auto cmds =
      parse_script("scenario walls 30\nscenario grass\ndump-scenario out/s.json\ndump-insight i.json\n", "t");
  ASSERT_EQ(cmds.size(), 4u);
  EXPECT_EQ(cmds[0].kind, ScriptCommand::Kind::scenario);
  EXPECT_EQ(cmds[0].arg, "walls");
  EXPECT_EQ(std::stof(cmds[0].value), 30.0f);
  EXPECT_EQ(std::stof(cmds[1].value), find_scenario("grass")->initial);
  EXPECT_EQ(cmds[2].kind, ScriptCommand::Kind::dump_scenario);
  EXPECT_EQ(cmds[3].arg, "i.json");
  EXPECT_THROW(parse_script("scenario nope\n", "t"), ScriptError);
  EXPECT_THROW(parse_script("scenario walls 400\n", "t"), ScriptError);
  EXPECT_THROW(parse_script("scenario walls abc\n", "t"), ScriptError);
  EXPECT_THROW(parse_script("dump-scenario\n", "t"), ScriptError);
  try {
    parse_script("scenario\n", "t");
    FAIL();
  } catch (const ScriptError& e) {
    EXPECT_NE(std::string(e.what()).find("t:1: scenario"), std::string::npos) << e.what();
  }
}
}  // namespace unity_test_app_scenarios
