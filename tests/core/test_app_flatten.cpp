// The GUI's flatten what-if (ui/app/flatten_worker.h): id lists, the
// prediction off the UI thread equal to core's flatten_what_if, cancelling,
// and the commit: the merged scene opened in AppState and built (not
// remembered as the last scene: it cannot be loaded again).
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "core/query/camera.h"
#include "core/scene/load.h"
#include "ui/app/app_state.h"
#include "ui/app/flatten_worker.h"
#include "ui/app/script.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_app_flatten {

using namespace accelviz;

template <typename Pred>
bool flatten_pump(AppState* app, Pred pred) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (std::chrono::steady_clock::now() < deadline) {
    if (app) app->update(48, 32);
    if (pred()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return false;
}

std::shared_ptr<const LoadedScene> flatten_forest() {
  auto s = std::make_shared<LoadedScene>();
  s->spec = "builtin:forest?size=1000&seed=4";
  s->scene = load_scene(s->spec);
  return s;
}

TEST(AppFlatten, InstanceIdListsParseAndFormat) {
  EXPECT_EQ(parse_instance_ids("0,2,5-7", 10), (std::vector<std::uint32_t>{0, 2, 5, 6, 7}));
  EXPECT_EQ(parse_instance_ids(" 7 3,3 ", 10), (std::vector<std::uint32_t>{3, 7}));  // sorted, distinct
  EXPECT_EQ(parse_instance_ids("all", 3), (std::vector<std::uint32_t>{0, 1, 2}));
  EXPECT_EQ(format_instance_ids({0, 2, 5, 6, 7, 9, 10}), "0,2,5-7,9,10");
  EXPECT_EQ(format_instance_ids({}), "");
  for (const char* bad : {"", "x", "5-2", "1-", "-3", "10", "0,11-12"}) {
    try {
      parse_instance_ids(bad, 10);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()).rfind("instances: ", 0), 0u) << e.what();
    }
  }
  EXPECT_NO_THROW(check_instance_ids("0-4000000000,all"));  // syntax only: nothing expanded
  EXPECT_THROW(check_instance_ids("4-2"), std::invalid_argument);
  // Spaces beside a comma are fine; an empty item between commas is a typo.
  EXPECT_EQ(parse_instance_ids("0 , 2,  3", 10), (std::vector<std::uint32_t>{0, 2, 3}));
  for (const char* bad : {"0,,1", "0, ,1", ",0", "0,", "0 ,"}) {
    try {
      check_instance_ids(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()),
                "instances: an empty item in '" + std::string(bad) + "' (expected e.g. 0,2,5-9 or all)");
    }
  }
}

TEST(AppFlatten, ScriptCommandsParse) {
  const auto cmds = parse_script("flatten 0,2,5-9\ndump-flatten /tmp/f.json\nflatten-commit\n", "s.txt");
  ASSERT_EQ(cmds.size(), 3u);
  EXPECT_EQ(cmds[0].kind, ScriptCommand::Kind::flatten);
  EXPECT_EQ(cmds[0].arg, "0,2,5-9");
  EXPECT_EQ(cmds[1].kind, ScriptCommand::Kind::dump_flatten);
  EXPECT_EQ(cmds[1].arg, "/tmp/f.json");
  EXPECT_EQ(cmds[2].kind, ScriptCommand::Kind::flatten_commit);
  EXPECT_EQ(command_name(ScriptCommand::Kind::flatten_commit), "flatten-commit");
  for (const char* bad : {"flatten\n", "flatten 5-2\n", "flatten-commit now\n", "dump-flatten\n"}) {
    try {
      parse_script(bad, "s.txt");
      ADD_FAILURE() << "accepted " << bad;
    } catch (const ScriptError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("s.txt:1: ", 0), 0u) << e.what();
    }
  }
}

TEST(AppFlatten, PredictionEqualsCoreAndCommitOpensTheMergedScene) {
  const auto forest = flatten_forest();
  const std::vector<std::uint32_t> ids = {1, 2, 3};
  FlattenRequest r;
  r.scene = forest;
  r.instances = ids;
  r.camera = camera_from_spec("", forest->scene, 4.0f / 3.0f);
  r.width = 32;
  r.height = 24;
  r.options.blas.threads = 2;
  r.options.tlas = r.options.blas;

  // Synchronously, with progress: the same figures as core's what-if.
  std::vector<double> fractions;
  const FlattenResult direct = run_flatten_request(
      r, [] { return true; }, [&](double f) { fractions.push_back(f); });
  ASSERT_TRUE(direct.figures);
  const FlattenWhatIf core = flatten_what_if(forest->scene, ids, r.camera, 32, 24, r.options);
  EXPECT_EQ(direct.figures->two_level.hits, core.two_level.hits);
  EXPECT_EQ(direct.figures->flattened.hits, core.flattened.hits);
  EXPECT_DOUBLE_EQ(direct.figures->two_level.mean_nodes, core.two_level.mean_nodes);
  EXPECT_DOUBLE_EQ(direct.figures->flattened.mean_instances, core.flattened.mean_instances);
  EXPECT_EQ(direct.figures->merged_triangles, 3u * forest->scene.instances[1].triangle_count);
  EXPECT_EQ(direct.figures->flattened.instances, forest->scene.instances.size() - 2);
  ASSERT_FALSE(fractions.empty());
  EXPECT_DOUBLE_EQ(fractions.back(), 1.0);
  EXPECT_THROW(run_flatten_request(r, [] { return false; }), BuildCancelled);

  const nlohmann::json j = flatten_result_json(direct, forest->spec);
  EXPECT_EQ(j["instances"], "1-3");
  EXPECT_EQ(j["merged_triangles"], direct.figures->merged_triangles);
  EXPECT_EQ(j["flattened"]["mean_prims"], direct.figures->flattened.mean_prims);

  // On the worker: the newest request wins and is published.
  FlattenWorker w;
  w.request(r);
  FlattenRequest r2 = r;
  r2.instances = {0, 4};
  const std::uint64_t id2 = w.request(r2);
  ASSERT_TRUE(flatten_pump(nullptr, [&] { return w.latest() && w.latest()->id == id2; }));
  EXPECT_EQ(w.latest()->instances, r2.instances);
  ASSERT_TRUE(w.latest()->figures);
  EXPECT_EQ(w.latest()->figures->merged_instances, 2u);

  // Commit: the merged scene, then AppState builds it.
  FlattenRequest c = r;
  c.kind = FlattenRequest::Kind::commit;
  const std::uint64_t cid = w.request(c);
  ASSERT_TRUE(flatten_pump(nullptr, [&] { return w.latest() && w.latest()->id == cid; }));
  const std::shared_ptr<const LoadedScene> merged = w.latest()->committed;
  ASSERT_TRUE(merged);
  EXPECT_TRUE(merged->in_memory);
  EXPECT_EQ(merged->spec, forest->spec + " [flattened 3 instances]");
  EXPECT_EQ(merged->scene.instances.size(), forest->scene.instances.size() - 2);
  EXPECT_EQ(merged->scene.triangles.size(), forest->scene.triangles.size());

  AppSettings settings;
  settings.config.structure.name = "tlas";
  AppState app(settings, [&](const std::string& spec) {
    if (spec != forest->spec) throw std::runtime_error(spec + ": cannot be loaded");
    return forest->scene;
  });
  app.open_scene(forest->spec);
  ASSERT_TRUE(flatten_pump(&app, [&] { return app.settled() && app.current(); }));
  app.open_loaded_scene(merged);
  ASSERT_TRUE(flatten_pump(&app, [&] { return app.settled() && app.current() && app.current()->scene == merged; }));
  EXPECT_EQ(app.scene_spec(), merged->spec);
  EXPECT_EQ(app.current()->accel->name(), "tlas");
  EXPECT_EQ(app.current()->accel->build_stats().extra.at("instances"),
            static_cast<double>(merged->scene.instances.size()));
  EXPECT_EQ(app.settings().last_scene, forest->spec);  // the in-memory scene is not remembered
  // Another structure builds over the merged scene without loading it.
  ASSERT_EQ(app.set_option("structure", "bvh"), "");
  ASSERT_TRUE(flatten_pump(&app, [&] { return app.settled() && app.current()->accel->name() == "bvh"; }));
  EXPECT_EQ(app.current()->scene, merged);
  EXPECT_TRUE(app.error().empty()) << app.error();
}

}  // namespace unity_test_app_flatten
