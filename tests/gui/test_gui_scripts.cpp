// Scripted runs of the real app: `accelviz --script FILE` opens its window
// on a private Xvfb server (llvmpipe), runs the commands through its main
// loop, and the test checks what it wrote: screenshots pixel by pixel, the
// picked ray against a brute-force trace computed here, the stats of each
// structure, and that bad input is reported while the app carries on.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "core/accel/brute_force.h"
#include "core/analysis/heatmap.h"
#include "core/query/camera.h"
#include "core/scene/load.h"
#include "tests/support/temp_dir.h"
#include "tests/support/xvfb_server.h"

namespace fs = std::filesystem;
using namespace accelviz;

namespace {

// Xvfb for this process, on the display number it picks itself (-displayfd),
// and the environment the app's window needs.
class GuiXServer : public test_support::PrivateXServer {
 public:
  GuiXServer() : PrivateXServer(ACCELVIZ_XVFB, "1280x800x24") {}
  void SetUp() override {
    PrivateXServer::SetUp();
    if (::testing::Test::HasFatalFailure()) return;
    unsetenv("WAYLAND_DISPLAY");
    // The window's GL comes from Mesa's libGL: llvmpipe, two rasteriser
    // threads (the CI machines have two cores).
    setenv("LIBGL_ALWAYS_SOFTWARE", "1", 1);
    setenv("GALLIUM_DRIVER", "llvmpipe", 1);
    setenv("LP_NUM_THREADS", "2", 1);
#ifdef ACCELVIZ_SANITIZE
    // Mesa's GLX driver leaks a little per process and is unloaded at
    // glfwTerminate, so LeakSanitizer can neither name nor suppress it (as
    // tests/gl's window test found). Address and UB checks stay on in the
    // app; its own code's leaks are covered by tests/core/test_app_*.
    setenv("ASAN_OPTIONS", "detect_leaks=0", 1);
#endif
  }
};

[[maybe_unused]] ::testing::Environment* const x_server = ::testing::AddGlobalTestEnvironment(new GuiXServer);

constexpr const char* kTeapot = "builtin:teapot?size=2000";
// Eye, target, fov: the teapot's body fills the middle of a 640×480 view.
constexpr const char* kCamera = "6,4,8,0,1.2,0,40";

using test_support::read_file;

nlohmann::json read_json(const fs::path& p) {
  const std::string text = read_file(p);
  if (text.empty()) ADD_FAILURE() << p << " is missing or empty";
  return nlohmann::json::parse(text.empty() ? "null" : text);
}

struct RunResult {
  int code = -1;
  std::string out;
  std::string err;
};

class GuiScript : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = (fs::temp_directory_path() / "accelviz-gui-XXXXXX").string();
    dir_ = mkdtemp(tmpl.data());
    // Where settings and default screenshots would go: both must stay empty.
    setenv("XDG_CONFIG_HOME", (dir_ / "config").c_str(), 1);
    setenv("XDG_PICTURES_DIR", (dir_ / "pictures").c_str(), 1);
  }
  void TearDown() override {
    EXPECT_FALSE(fs::exists(dir_ / "config")) << "a scripted run wrote settings";
    if (!HasFailure()) fs::remove_all(dir_);
  }

  fs::path path(const std::string& name) const { return dir_ / name; }

  /// Writes the script and runs `accelviz --script` on it (plus `args`).
  RunResult run(const std::string& script, const std::string& args = "") {
    const fs::path file = dir_ / "script.txt";
    std::ofstream(file) << script;
    const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string cmd = std::string("'") + ACCELVIZ_BIN + "' --script '" + file.string() + "' " + args + " > '" +
                            out.string() + "' 2> '" + err.string() + "'";
    const int status = std::system(cmd.c_str());
    RunResult r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = read_file(out);
    r.err = read_file(err);
    return r;
  }

  fs::path dir_;
};

// Colour distance (sum over channels).
int distance(glm::u8vec3 a, glm::u8vec3 b) {
  return std::abs(a.x - b.x) + std::abs(a.y - b.y) + std::abs(a.z - b.z);
}

std::size_t distinct_colours(const RgbImage& img) {
  std::set<std::uint32_t> colours;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const glm::u8vec3 c = img.at(x, y);
      colours.insert(c.x << 16 | c.y << 8 | c.z);
    }
  return colours.size();
}

// Pixels of the region within `tol` of colour `c`.
int count_near(const RgbImage& img, int x0, int y0, int x1, int y1, glm::u8vec3 c, int tol) {
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) n += distance(img.at(x, y), c) <= tol;
  return n;
}

}  // namespace

TEST_F(GuiScript, ScreenshotShowsTheMeshAndTheLegend) {
  const RunResult r = run(std::string("open ") + kTeapot + "\n" +
                          "size 640 480\n"
                          "camera " +
                          kCamera +
                          "\n"
                          "set boxes off\n"
                          "wait\n"
                          "screenshot " +
                          path("mesh.png").string() +
                          "\n"
                          "set heatmap blend\n"
                          "set opacity 0.8\n"
                          "wait\n"
                          "screenshot " +
                          path("heatmap.png").string() +
                          "\n"
                          "quit\n");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find(path("mesh.png").string()), std::string::npos) << "the path written is printed";

  const RgbImage mesh = read_png(path("mesh.png").string());
  const RgbImage heat = read_png(path("heatmap.png").string());
  // The 3D view is 640×480; the caption strip is added below it.
  ASSERT_EQ(mesh.width, 640);
  ASSERT_GT(mesh.height, 480);
  ASSERT_EQ(heat.width, 640);

  // Not blank, and the teapot stands out from the background.
  EXPECT_GT(distinct_colours(mesh), 50u);
  const glm::u8vec3 background = mesh.at(4, 4);
  EXPECT_EQ(distance(background, mesh.at(635, 475)), 0) << "corners show the background";
  EXPECT_GT(distance(mesh.at(320, 240), background), 60) << "the teapot is at the centre";
  int on_mesh = 0;
  for (int y = 0; y < 480; ++y)
    for (int x = 0; x < 640; ++x) on_mesh += distance(mesh.at(x, y), background) > 30;
  EXPECT_GT(on_mesh, 640 * 480 / 20);
  EXPECT_LT(on_mesh, 640 * 480 * 9 / 10);

  // The legend at the right edge: the top of viridis (yellow) and its
  // bottom (dark purple) appear there with the heatmap on, not without.
  const glm::u8vec3 top = to_rgb8(colormap(ColorMap::viridis, 1.0f));
  const glm::u8vec3 bottom = to_rgb8(colormap(ColorMap::viridis, 0.0f));
  EXPECT_GT(count_near(heat, 512, 0, 640, 480, top, 12), 40);
  EXPECT_GT(count_near(heat, 512, 0, 640, 480, bottom, 12), 40);
  EXPECT_EQ(count_near(mesh, 512, 0, 640, 480, top, 12), 0);
  // The heatmap changes the teapot's colours.
  EXPECT_GT(distance(heat.at(320, 240), mesh.at(320, 240)), 30);

  // The caption under the picture and the side-car next to it.
  int caption_text = 0;
  for (int y = 481; y < heat.height; ++y)
    for (int x = 0; x < 640; ++x) caption_text += heat.at(x, y).x > 150;
  EXPECT_GT(caption_text, 100);
  const nlohmann::json side = read_json(path("heatmap.json"));
  EXPECT_EQ(side["scene"], kTeapot);
  EXPECT_EQ(side["camera"]["spec"], kCamera);
  EXPECT_EQ(side["heatmap"]["display"], "blend");
  EXPECT_EQ(side["structure"]["name"], "bvh");
  EXPECT_EQ(side["size"]["width"], 640);
  // The build it came from, as --version says it (a bug report's screenshot names its commit).
  ASSERT_TRUE(side.contains("program"));
  const std::string line = side["program"].value("line", "");
  EXPECT_EQ(line.rfind("accelviz ", 0), 0u) << side["program"];
  EXPECT_NE(line.find("(commit " + side["program"].value("commit", "?")), std::string::npos) << side["program"];
  EXPECT_FALSE(fs::exists(dir_ / "pictures")) << "explicit paths only";
}

// reload-shaders (F5 in the window): a folder's files win over the built-in
// shaders from then on. A mesh shader that paints everything magenta turns the
// teapot magenta; a broken one is refused with its file named, and the script
// stops there (exit 1).
TEST_F(GuiScript, ReloadShadersTakesTheFolderOrNamesTheBrokenFile) {
  fs::create_directories(path("magenta"));
  std::ofstream(path("magenta") / "mesh.frag") << "#version 450 core\nout vec4 frag_color;\n"
                                                  "void main() { frag_color = vec4(1.0, 0.0, 1.0, 1.0); }\n";
  fs::create_directories(path("broken"));
  std::ofstream(path("broken") / "mesh.frag") << "#version 450 core\nout vec4 frag_color;\nvoid main( {\n";
  const std::string head =
      std::string("open ") + kTeapot + "\nsize 320 240\ncamera " + kCamera + "\nset boxes off\nwait\n";
  const RunResult r =
      run(head + "screenshot " + path("before.png").string() + "\nreload-shaders " + path("magenta").string() +
          "\ndump-stats " + path("stats.json").string() + "\nscreenshot " + path("after.png").string() + "\nquit\n");
  ASSERT_EQ(r.code, 0) << r.err;
  const RgbImage before = read_png(path("before.png").string()), after = read_png(path("after.png").string());
  const glm::u8vec3 magenta(255, 0, 255);
  EXPECT_EQ(count_near(before, 0, 0, 320, 240, magenta, 30), 0);
  EXPECT_GT(count_near(after, 0, 0, 320, 240, magenta, 30), 320 * 240 / 20) << "the teapot is drawn magenta";
  EXPECT_NE(read_json(path("stats.json"))["message"].get<std::string>().find("shaders reloaded (files in " +
                                                                             path("magenta").string()),
            std::string::npos);

  const RunResult bad = run(head + "reload-shaders " + path("broken").string() + "\nquit\n");
  EXPECT_EQ(bad.code, 1);
  EXPECT_NE(bad.err.find((path("broken") / "mesh.frag").string() + ":3:"), std::string::npos) << bad.err;
  EXPECT_NE(bad.err.find("shaders not reloaded"), std::string::npos) << bad.err;
  const RunResult missing = run(head + "reload-shaders " + path("nowhere").string() + "\nquit\n");
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.err.find("nowhere: not a folder"), std::string::npos) << missing.err;
}

// The BVH's EPO measurement after a build is quadratic on a scene whose
// centroids are all equal: 50,000 such triangles took minutes, and neither a
// newer `open` nor quitting could stop it (the app hung on exit). It now
// asks the build's progress whether to go on.
TEST_F(GuiScript, ANewerOpenAndQuitDoNotWaitForTheEpoMeasurement) {
  const auto t0 = std::chrono::steady_clock::now();
  const RunResult r = run(std::string("open builtin:same-centroid?size=50000\nsize 320 240\nframes 30\nopen ") +
                          kTeapot + "\nwait\ndump-stats " + path("stats.json").string() +
                          "\nopen builtin:same-centroid?size=50000\nframes 30\nquit\n");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(read_json(path("stats.json"))["scene"], kTeapot);
  // A guard against the hang, not a timing: the run took minutes before.
  EXPECT_LT(seconds, 60.0);
}

// flatten-commit right after an open committed the old scene's prediction
// and threw the open away: it now waits for the scene, which has none.
TEST_F(GuiScript, FlattenCommitAfterAnOpenDoesNotDropTheOpen) {
  const RunResult r =
      run(std::string("open builtin:forest?size=5000\nsize 320 240\nstructure tlas\nwait\nflatten 0\n") + "open " +
          kTeapot + "\nflatten-commit\nquit\n");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("flatten-commit: no prediction of the shown scene"), std::string::npos) << r.err;
  const RunResult after =
      run(std::string("open builtin:forest?size=5000\nsize 320 240\nstructure tlas\nwait\n") + "flatten 0\nopen " +
          kTeapot + "\nwait\ndump-stats " + path("s.json").string() + "\nquit\n");
  ASSERT_EQ(after.code, 0) << after.err;
  EXPECT_EQ(read_json(path("s.json"))["scene"], kTeapot);
}

// Dumps, like screenshots, never replace a file: a dump-stats named after a
// screenshot's side-car silently replaced it.
TEST_F(GuiScript, DumpsNeverReplaceAFile) {
  const std::string head = std::string("open ") + kTeapot + "\nsize 320 240\ncamera " + kCamera + "\nwait\n";
  const RunResult shot = run(head + "screenshot " + path("a.png").string() + "\nquit\n");
  ASSERT_EQ(shot.code, 0) << shot.err;
  const std::string sidecar = read_file(path("a.json"));
  ASSERT_FALSE(sidecar.empty());
  const RunResult r = run(head + "dump-stats " + path("a.json").string() + "\nquit\n");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(path("a.json").string() + ": exists (not overwritten)"), std::string::npos) << r.err;
  EXPECT_EQ(read_file(path("a.json")), sidecar);
  std::ofstream(path("precious.json")) << "mine";
  const RunResult ray = run(head + "click 160 120\ndump-ray " + path("precious.json").string() + "\nquit\n");
  EXPECT_EQ(ray.code, 1);
  EXPECT_EQ(read_file(path("precious.json")), "mine");
  const RunResult deep = run(head + "dump-stats " + path("no/such/x.json").string() + "\nquit\n");
  EXPECT_EQ(deep.code, 1) << "a missing folder is an error, as for screenshots";
  EXPECT_FALSE(fs::exists(path("no")));
}

// A ray clicked in one view and shown from another: the screenshot's side-car
// script casts the same ray again (it set the new camera first and clicked
// there: another ray, another triangle).
TEST_F(GuiScript, TheSideCarReplaysARayClickedInAnEarlierView) {
  const RunResult r = run(std::string("open ") + kTeapot + "\nsize 320 240\ncamera " + kCamera +
                          "\nwait\nclick 160 120\ndump-ray " + path("clicked.json").string() +
                          "\ncamera 12,5,-2,0,1,0,45\nwait\nscreenshot " + path("side.png").string() + "\nquit\n");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json car = read_json(path("side.json"));
  ASSERT_FALSE(car["ray_camera"].is_null()) << car.dump();
  std::string replay;
  for (const std::string line : car["reproduce"]["script"]) {
    if (line.rfind("screenshot ", 0) == 0) {
      replay += "dump-ray " + path("replayed.json").string() + "\n";
      continue;
    }
    replay += line + "\n";
  }
  const RunResult again = run(replay);
  ASSERT_EQ(again.code, 0) << again.err << "\n" << replay;
  const nlohmann::json a = read_json(path("clicked.json")), b = read_json(path("replayed.json"));
  EXPECT_EQ(a["hit"]["prim"], b["hit"]["prim"]);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(a["ray"]["origin"][k].get<double>(), b["ray"]["origin"][k].get<double>(), 1e-4);
    EXPECT_NEAR(a["ray"]["direction"][k].get<double>(), b["ray"]["direction"][k].get<double>(), 1e-4);
  }
}

TEST_F(GuiScript, ClickCastsThePixelRayAndReplaysItsTraversal) {
  const RunResult r = run(std::string("open ") + kTeapot + "\n" +
                          "size 640 480\n"
                          "camera " +
                          kCamera +
                          "\n"
                          "wait\n"
                          "click 320 240\n"
                          "dump-ray " +
                          path("ray-dump.json").string() +
                          "\n"
                          "step 0\n"
                          "step next\n"
                          "dump-ray " +
                          path("ray-dump1.json").string() +
                          "\n"
                          "screenshot " +
                          path("ray.png").string() +
                          "\n"
                          "quit\n");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = read_json(path("ray-dump.json"));
  ASSERT_EQ(j["size"], nlohmann::json::array({640, 480}));
  ASSERT_FALSE(j["hit"].is_null()) << "the centre pixel hits the teapot";

  // The same pixel's ray, traced here by brute force.
  const Scene scene = load_scene(kTeapot);
  const Camera cam = camera_from_spec(kCamera, scene, 640.0f / 480.0f);
  const Ray ray = primary_ray(cam, 320, 240, 640, 480);
  const Hit expected = BruteForce(scene.triangles).closest_hit(ray, {});
  ASSERT_TRUE(expected.valid());
  EXPECT_EQ(j["hit"]["prim"].get<std::uint32_t>(), expected.prim);
  EXPECT_NEAR(j["hit"]["t"].get<float>(), expected.t, 1e-5f * expected.t);
  EXPECT_NEAR(j["ray"]["direction"][0].get<float>(), ray.direction.x, 1e-6f);
  EXPECT_NEAR(j["ray"]["origin"][2].get<float>(), ray.origin.z, 1e-5f);

  // The traversal: entered nodes, primitive tests, the hit among them.
  const auto& steps = j["steps"];
  ASSERT_FALSE(steps.empty());
  int entered = 0, hit_steps = 0;
  for (const auto& s : steps) {
    entered += s["kind"] == "entered";
    hit_steps += s["kind"] == "prim-hit" && s["id"] == expected.prim;
  }
  EXPECT_GT(entered, 0);
  EXPECT_EQ(entered, j["entered_nodes"].get<int>());
  EXPECT_GE(hit_steps, 1);
  EXPECT_EQ(j["replay_step"].get<std::size_t>(), steps.size() - 1) << "a new ray shows its whole traversal";
  EXPECT_EQ(read_json(path("ray-dump1.json"))["replay_step"], 1) << "step 0, then next";
  // The scene has a light: one shadow ray towards it.
  EXPECT_EQ(j["shadows"].size(), scene.lights.size());
  EXPECT_TRUE(fs::exists(path("ray.png")));
  // Stepping replays the same ray; it does not cast a new one.
  const nlohmann::json stepped = read_json(path("ray-dump1.json"));
  EXPECT_EQ(stepped["ray"], j["ray"]);
  EXPECT_EQ(stepped["hit"], j["hit"]);
}

TEST_F(GuiScript, SwitchingStructuresRebuildsAndTheHeatmapFollows) {
  std::string script = std::string("open ") + kTeapot + "\nsize 640 480\ncamera " + kCamera + "\nset heatmap full\n";
  for (const char* s : {"bvh", "kdtree", "grid"})
    script += std::string("structure ") + s + "\nwait\ndump-stats " + path(std::string(s) + "-stats.json").string() +
              "\nscreenshot " + path(std::string(s) + ".png").string() + "\n";
  const RunResult r = run(script + "quit\n");
  ASSERT_EQ(r.code, 0) << r.err;
  std::set<std::uint64_t> node_counts;
  std::vector<RgbImage> shots;
  for (const char* s : {"bvh", "kdtree", "grid"}) {
    SCOPED_TRACE(s);
    const nlohmann::json j = read_json(path(std::string(s) + "-stats.json"));
    EXPECT_EQ(j["structure"], s);
    EXPECT_EQ(j["scene"], kTeapot);
    EXPECT_EQ(j["building"], false);
    EXPECT_EQ(j["error"], "");
    ASSERT_FALSE(j["build"].is_null());
    EXPECT_GT(j["build"]["nodes"].get<std::uint64_t>(), 0u);
    node_counts.insert(j["build"]["nodes"].get<std::uint64_t>());
    // The view's figures come from a complete heatmap of this structure.
    ASSERT_FALSE(j["view"].is_null());
    EXPECT_EQ(j["view"]["structure"], s);
    EXPECT_EQ(j["view"]["complete"], true);
    EXPECT_EQ(j["view"]["rays"], 640 * 480);
    EXPECT_GT(j["view"]["mean_nodes"].get<double>(), 0.0);
    EXPECT_GT(j["view"]["max_prims"].get<double>(), 0.0);
    EXPECT_GT(j["view"]["rays_per_s"].get<double>(), 0.0);
    shots.push_back(read_png(path(std::string(s) + ".png").string()));
    EXPECT_GT(distinct_colours(shots.back()), 20u) << "the heatmap is drawn";
  }
  EXPECT_EQ(node_counts.size(), 3u) << "three different structures were built";
  EXPECT_NE(shots[0].pixels, shots[1].pixels);
  EXPECT_NE(shots[1].pixels, shots[2].pixels);
  for (const char* s : {"bvh", "kdtree", "grid"})
    EXPECT_EQ(read_json(path(std::string(s) + "-stats.json"))["build"]["inspectable"], true) << s;
}

#ifdef ACCELVIZ_HAVE_EMBREE
// Embree keeps its tree and per-ray counters to itself: the Stats panel says
// n/a rather than 0 nodes, and its counter heatmap is 0 everywhere (the View
// panel says so); its hits are shown.
TEST_F(GuiScript, EmbreeShownSaysItCountsNothing) {
  const RunResult r =
      run(std::string("open ") + kTeapot + "\nsize 320 240\ncamera " + kCamera +
          "\nset heatmap full\nstructure embree\nwait\ndump-stats " + path("e.json").string() + "\nquit\n");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = read_json(path("e.json"));
  EXPECT_EQ(j["structure"], "embree");
  EXPECT_EQ(j["build"]["inspectable"], false);
  EXPECT_EQ(j["view"]["mean_nodes"].get<double>(), 0.0);
  EXPECT_GT(j["view"]["hits"].get<int>(), 0);
}
#endif

TEST_F(GuiScript, ABadScenePathIsReportedAndTheAppKeepsRunning) {
  const std::string missing = path("no-such-model.glb").string();
  const RunResult r =
      run(std::string("open ") + kTeapot + "\nsize 640 480\nwait\n" + "open " + missing + "\nwait\n" + "dump-stats " +
          path("after-error.json").string() + "\n" + "structure octree\nwait\n" + "dump-stats " +
          path("after-octree.json").string() + "\n" + "screenshot " + path("still-running.png").string() + "\nquit\n");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json e = read_json(path("after-error.json"));
  const std::string error = e["error"];
  EXPECT_NE(error.find("no-such-model.glb"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos);
  EXPECT_EQ(e["scene"], kTeapot) << "the scene shown stays";
  EXPECT_NE(r.err.find("no-such-model.glb"), std::string::npos) << "also reported on stderr";
  const nlohmann::json o = read_json(path("after-octree.json"));
  EXPECT_EQ(o["structure"], "octree");
  EXPECT_EQ(o["scene"], kTeapot);
  EXPECT_GT(distinct_colours(read_png(path("still-running.png").string())), 20u);
}

TEST_F(GuiScript, ScriptErrorsNameTheLineAndExitWithOne) {
  // A bad line is found before anything runs.
  RunResult r = run("wait\n# comment\nset bukets 4\nquit\n");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find((dir_ / "script.txt").string() + ":3: set: unknown option 'bukets'"), std::string::npos)
      << r.err;
  // A command that fails while running.
  r = run(std::string("open ") + kTeapot + "\nsize 640 480\nwait\nclick 9000 10\nquit\n");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(":4: click: pixel 9000,10 is outside the 640x480 view"), std::string::npos) << r.err;
  // A screenshot never overwrites.
  std::ofstream(path("taken.png")) << "mine";
  r = run(std::string("open ") + kTeapot + "\nwait\nscreenshot " + path("taken.png").string() + "\nquit\n");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(":3: screenshot: " + path("taken.png").string() + ": exists (not overwritten)"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(read_file(path("taken.png")), "mine");
}

// The panels a scene or structure calls for: opening one that is not shown
// fails with the reason (it used to wait unseen and pop open with a later
// scene); closing it does nothing; a failing command's name is said once.
TEST_F(GuiScript, OpeningAPanelTheSceneDoesNotCallForSaysWhy) {
  RunResult r = run(std::string("open ") + kTeapot + "\nwait\nwindow open Dynamics\nquit\n");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(
      r.err.find(":3: window: Dynamics is not shown now: " + std::string(kTeapot) + ": per-frame updates are off ("),
      std::string::npos)
      << r.err;
  r = run(std::string("open ") + kTeapot + "\nstructure kdtree\nwait\nwindow open Flatten what-if\nquit\n");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(":4: window: Flatten what-if is not shown now: the structure is kdtree; the panel shows while a "
                       "tlas is shown"),
            std::string::npos)
      << r.err;
  r = run(std::string("open ") + kTeapot + "\nwait\nwindow close Dynamics\nwindow close Flatten what-if\nquit\n");
  EXPECT_EQ(r.code, 0) << r.err;
  r = run(std::string("open ") + kTeapot + "\nwait\nplay 2\nquit\n");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(":3: play: " + std::string(kTeapot) + ": per-frame updates are off"), std::string::npos)
      << r.err;
  // A panel that is shown opens as before.
  r = run("open builtin:dynamic?size=6000\nwait\nwindow open Dynamics\nwait\nquit\n");
  EXPECT_EQ(r.code, 0) << r.err;
}

TEST_F(GuiScript, SceneArgumentOpensBeforeTheScript) {
  const RunResult r = run("wait\ndump-stats " + path("s.json").string() + "\nquit\n", "'builtin:teapot?size=300'");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = read_json(path("s.json"));
  EXPECT_EQ(j["scene"], "builtin:teapot?size=300");
  EXPECT_EQ(j["structure"], "bvh");
  EXPECT_EQ(j["camera"], "") << "the default view";
}

// Insight views: the Scenarios window measures the lecture's cases, moving
// its slider moves the figures the documented way (rotated walls cost the
// BVH more than aligned ones), and the view's insight (predicted vs
// measured, traversal modes, hot nodes, SAH explainer) is consistent.
TEST_F(GuiScript, InsightScenariosAndPredictedVsMeasured) {
  const RunResult r = run(std::string("open ") + kTeapot + "\n" + "size 640 480\ncamera " + kCamera +
                          "\nwait\n"
                          "scenario walls 0\n"
                          "dump-scenario " +
                          path("aligned.json").string() +
                          "\n"
                          "scenario walls 45\n"
                          "dump-scenario " +
                          path("rotated.json").string() +
                          "\n"
                          "dump-insight " +
                          path("insight.json").string() + "\nquit\n");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json a = read_json(path("aligned.json")), b = read_json(path("rotated.json"));
  ASSERT_EQ(a["rows"].size(), 1u);
  ASSERT_EQ(b["rows"].size(), 1u);
  EXPECT_EQ(a["value"], 0.0);
  EXPECT_EQ(b["value"], 45.0);
  EXPECT_GT(b["rows"][0]["cost_per_ray"].get<double>(), a["rows"][0]["cost_per_ray"].get<double>());
  EXPECT_GT(b["rows"][0]["leaf_volume_ratio"].get<double>(), a["rows"][0]["leaf_volume_ratio"].get<double>());

  const nlohmann::json in = read_json(path("insight.json"));
  ASSERT_TRUE(in["is_bvh"].get<bool>());
  EXPECT_GT(in["cost"]["sah"].get<double>(), 1.0);
  EXPECT_GT(in["cost"]["root_rays"].get<int>(), 0);
  EXPECT_GT(in["cost"]["cost_per_ray"].get<double>(), 1.0);
  const auto& m = in["modes"];
  EXPECT_GE(m["back-to-front"]["nodes_per_ray"].get<double>(), m["front-to-back"]["nodes_per_ray"].get<double>());
  EXPECT_GE(m["x-ray"]["prims_per_ray"].get<double>(), m["front-to-back"]["prims_per_ray"].get<double>());
  EXPECT_EQ(m["x-ray"]["culled_per_ray"].get<double>(), 0.0);
  EXPECT_GT(m["front-to-back"]["culled_per_ray"].get<double>(), 0.0);
  ASSERT_FALSE(in["hot"].empty());
  EXPECT_EQ(in["hot"][0]["node"], 0);  // every ray that enters anything enters the root
  EXPECT_EQ(in["hot"][0]["visits"].get<int>(), in["cost"]["root_rays"].get<int>());
  EXPECT_EQ(in["explainer"]["node"], 0);
  EXPECT_GT(in["explainer"]["prims"].get<int>(), 1000);
  EXPECT_EQ(in["explainer"]["decision"], "split");
}

// The other lecture scenarios, each at two slider positions: the figures
// move the way each caption says.
TEST_F(GuiScript, EveryScenarioSliderMovesItsFiguresTheDocumentedWay) {
  struct Case {
    const char* id;
    float low, high;
  };
  const Case cases[] = {{"teapot-stadium", 10, 30},
                        {"same-centroid", 200, 1000},
                        {"same-bounds", 200, 1000},
                        {"grass", 1000, 4000},
                        {"growth", 4000, 8000}};
  std::string script = std::string("open ") + kTeapot + "\nsize 640 480\nwait\n";
  for (const Case& c : cases)
    for (const bool high : {false, true}) {
      const std::string name = std::string(c.id) + (high ? "-high" : "-low") + ".json";
      script += "scenario " + std::string(c.id) + " " + std::to_string(high ? c.high : c.low) + "\n" +
                "dump-scenario " + path(name).string() + "\n";
    }
  script += "quit\n";
  const RunResult r = run(script);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto row = [](const nlohmann::json& j, const std::string& structure, bool last = false) {
    nlohmann::json found;
    for (const auto& x : j["rows"])
      if (x["structure"] == structure) {
        found = x;
        if (!last) break;
      }
    EXPECT_FALSE(found.is_null()) << structure;
    return found;
  };
  const auto low = [&](const char* id) { return read_json(path(std::string(id) + "-low.json")); };
  const auto high = [&](const char* id) { return read_json(path(std::string(id) + "-high.json")); };
  // Teapot in a stadium: as the stadium grows the grid's primitive tests per ray climb.
  EXPECT_GT(row(high("teapot-stadium"), "grid")["prims_per_ray"].get<double>(),
            row(low("teapot-stadium"), "grid")["prims_per_ray"].get<double>());
  // One centroid / one box for all: cost per ray grows with N (boxes that all hold one point overlap
  // there; with one box for all nothing separates the primitives).
  for (const char* id : {"same-centroid", "same-bounds"})
    EXPECT_GT(row(high(id), "bvh")["cost_per_ray"].get<double>(), row(low(id), "bvh")["cost_per_ray"].get<double>())
        << id;
  // Grass: the slider is the field's size; all three structures measured on it.
  for (const char* st : {"grid", "bvh", "kdtree"})
    EXPECT_GT(row(high("grass"), st)["triangles"].get<double>(), row(low("grass"), st)["triangles"].get<double>())
        << st;
  // Growth: from N/64 to N a grid's nodes per ray grow (about N^(1/3)); the largest N follows the slider.
  const nlohmann::json g = high("growth");
  EXPECT_GT(row(g, "grid", true)["nodes_per_ray"].get<double>(), row(g, "grid")["nodes_per_ray"].get<double>());
  EXPECT_GT(row(g, "bvh", true)["triangles"].get<double>(), row(low("growth"), "bvh", true)["triangles"].get<double>());
}

// The two-level views of issue 10, in the real window: the node boxes at the
// top level (TLAS nodes, instance boxes) and the bottom level (every
// instance's BLAS in world space, or one instance's), per-instance colours,
// and a played frame that is the animator's own tree with its instance
// overlap per frame.
TEST_F(GuiScript, TwoLevelBoxLevelsInstanceColoursAndPlayedFrames) {
  const RunResult r =
      run("open builtin:dynamic?size=1200\nstructure tlas\nsize 320 240\nset box-mode leaves\nwait\nscreenshot " +
          path("top.png").string() + "\ndump-stats " + path("top-stats.json").string() +
          "\nset box-level blas\nset instance-colors on\nwait\nscreenshot " + path("blas.png").string() +
          "\ndump-stats " + path("blas-stats.json").string() + "\nset box-instance 0\nwait\ndump-stats " +
          path("one.json").string() + "\nplay 2\nwait\ndump-dynamics " + path("dyn.json").string() + "\nscreenshot " +
          path("played.png").string() + "\nquit\n");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json top = read_json(path("top-stats.json"));
  const nlohmann::json blas = read_json(path("blas-stats.json"));
  const nlohmann::json one = read_json(path("one.json"));
  ASSERT_EQ(top["structure"], "tlas") << top.dump();
  // Leaves: one box per instance at the top level; every instance's BLAS
  // leaves at the bottom level; one instance's alone fewer still.
  const auto instances = top["build"]["extra"]["instances"].get<double>();
  EXPECT_EQ(top["boxes"]["drawn"].get<double>(), instances);
  EXPECT_GT(blas["boxes"]["drawn"].get<std::uint64_t>(), top["boxes"]["drawn"].get<std::uint64_t>());
  EXPECT_GT(one["boxes"]["drawn"].get<std::uint64_t>(), 0u);
  EXPECT_LT(one["boxes"]["drawn"].get<std::uint64_t>(), blas["boxes"]["drawn"].get<std::uint64_t>());
  EXPECT_FALSE(top["boxes"]["instance_colors"].get<bool>());
  EXPECT_TRUE(blas["boxes"]["instance_colors"].get<bool>());
  // Instance colours fill the mesh with saturated colour where it was grey
  // (only the box lines were coloured before).
  const auto saturated = [](const RgbImage& img) {
    int n = 0;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) {
        const glm::u8vec3 c = img.at(x, y);
        n += std::max({c.x, c.y, c.z}) - std::min({c.x, c.y, c.z}) > 60;
      }
    return n;
  };
  EXPECT_GT(saturated(read_png(path("blas.png").string())), 2 * saturated(read_png(path("top.png").string())));
  // The played frames: the animator's own tree, the overlap measured on each.
  const nlohmann::json d = read_json(path("dyn.json"));
  ASSERT_TRUE(d["dynamics"].is_object()) << d.dump();
  // The build that measured the frames' timings, as animate --json's first line names it.
  ASSERT_TRUE(d["program"].is_object()) << d.dump();
  EXPECT_EQ(d["program"]["line"].get<std::string>().rfind("accelviz ", 0), 0u) << d.dump();
  const auto& shown = d["dynamics"]["shown_frame"];
  ASSERT_TRUE(shown.is_object()) << d.dump();
  EXPECT_TRUE(shown["animator_tree"].get<bool>());
  EXPECT_GT(shown["node_count"].get<double>(), 0.0);
  for (const auto& f : d["dynamics"]["history"]) {
    EXPECT_GT(f["overlap_area"].get<double>(), 0.0) << f.dump();
    EXPECT_GT(f["overlap_pairs"].get<double>(), 0.0) << f.dump();
  }
  EXPECT_TRUE(fs::exists(path("played.png")));
}

// The Dynamics panel plays builtin:dynamic off the UI thread: `play 3` waits
// for three stepped frames, whose figures come from a SceneAnimator over the
// scene's two-level structure. A static OBJ without lights reports shadow
// rays and per-frame updates off, and a force turns shadow rays on, said so.
TEST_F(GuiScript, DynamicsPanelPlaysFramesAndEffectsFollowTheScene) {
  const RunResult r = run("open builtin:dynamic?size=6000\nsize 480 360\nwait\ndump-stats " +
                          path("rest.json").string() + "\nplay 3\nwait\ndump-dynamics " + path("dyn.json").string() +
                          "\ndump-stats " + path("frame.json").string() + "\nquit\n");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json d = read_json(path("dyn.json"));
  ASSERT_TRUE(d["dynamics"].is_object()) << d.dump();
  EXPECT_GE(d["dynamics"]["frames_stepped"].get<int>(), 3);
  EXPECT_EQ(d["dynamics"]["error"], "");
  const auto& h = d["dynamics"]["history"];
  ASSERT_GE(h.size(), 3u);
  const auto& last = h.back();
  EXPECT_GT(last["moved_instances"].get<int>(), 0);
  EXPECT_GT(last["tlas_rebuild_ms"].get<double>(), 0.0);
  EXPECT_EQ(last["refits"].get<int>() + last["rebuilds"].get<int>(), 1);  // the one grass BLAS
  EXPECT_GT(last["refit_ms"].get<double>() + last["rebuild_ms"].get<double>(), 0.0);
  EXPECT_GT(last["sah_refit"].get<double>(), 0.0);
  EXPECT_GT(last["sah_rebuilt"].get<double>(), 0.0);
  std::map<std::string, bool> on;
  for (const auto& e : d["effects"]) on[e["name"].get<std::string>()] = e["on"].get<bool>();
  EXPECT_TRUE(on["per-frame-updates"]);
  EXPECT_TRUE(on["two-level"]);
  // The view shows the last frame stepped: its structure, and the heatmap traced on it.
  const auto& shown = d["dynamics"]["shown_frame"];
  ASSERT_TRUE(shown.is_object()) << d.dump();
  EXPECT_GT(shown["time"].get<double>(), 0.0);
  const nlohmann::json rest_view = read_json(path("rest.json"))["view"];
  const nlohmann::json frame_view = read_json(path("frame.json"))["view"];
  EXPECT_NE(frame_view["mean_nodes"].get<double>(), rest_view["mean_nodes"].get<double>());

  const fs::path obj = path("tri.obj");
  std::ofstream(obj) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n";
  const RunResult s =
      run("open " + obj.string() + "\nwait\ndump-dynamics " + path("static.json").string() + "\ndump-stats " +
          path("static_stats.json").string() + "\nforce-effect shadow-rays\nwait\ndump-dynamics " +
          path("forced.json").string() + "\ndump-stats " + path("forced_stats.json").string() + "\nquit\n");
  ASSERT_EQ(s.code, 0) << s.err;
  for (const char* file : {"static.json", "forced.json"}) {
    const nlohmann::json st = read_json(path(file));
    EXPECT_TRUE(st["dynamics"].is_null()) << file << ": nothing animates, nothing is stepped";
    for (const auto& e : st["effects"]) {
      if (e["name"] == "per-frame-updates") {
        EXPECT_FALSE(e["on"].get<bool>()) << file;
      }
      if (e["name"] != "shadow-rays") continue;
      const bool forced = std::string(file) == "forced.json";
      EXPECT_EQ(e["on"].get<bool>(), forced) << file;
      EXPECT_EQ(e["forced"].get<bool>(), forced) << file;
      EXPECT_NE(e["reason"].get<std::string>().find("no lights"), std::string::npos) << e.dump();
    }
  }
  // The counters: no lights, none traced; forced on, one per primary hit (to the synthetic light).
  const nlohmann::json sv = read_json(path("static_stats.json"))["view"];
  const nlohmann::json fv = read_json(path("forced_stats.json"))["view"];
  EXPECT_EQ(sv["shadow_rays"].get<std::uint64_t>(), 0u);
  EXPECT_GT(fv["shadow_rays"].get<std::uint64_t>(), 0u);
  EXPECT_EQ(fv["shadow_rays"].get<std::uint64_t>(), fv["hits"].get<std::uint64_t>());
}

// Hot nodes in the window: a heatmap region selected with `select-region`
// (3D-view pixels) reports the nodes and primitives its rays touched, fewer
// for a smaller region inside it; a click in the 3D view selects the leaf
// its hit lies in, with its path from the root.
TEST_F(GuiScript, InsightRegionSelectionAndClickSelectsTheHitLeaf) {
  const RunResult r = run(std::string("open ") + kTeapot + "\nsize 640 480\ncamera " + kCamera +
                          "\nwait\n"
                          "select-region 160 120 480 360\n"
                          "dump-insight " +
                          path("big.json").string() +
                          "\nselect-region 330 250 300 220\n"  // corners in any order
                          "dump-insight " +
                          path("small.json").string() +
                          "\nclick 320 240\n"
                          "dump-insight " +
                          path("click.json").string() + "\ndump-ray " + path("ray.json").string() + "\nquit\n");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json big = read_json(path("big.json")), small = read_json(path("small.json"));
  ASSERT_TRUE(big["region"].is_object()) << big.dump();
  ASSERT_TRUE(small["region"].is_object()) << small.dump();
  EXPECT_GT(small["region"]["nodes"].get<int>(), 0);
  EXPECT_GT(small["region"]["prims"].get<int>(), 0);
  EXPECT_GT(big["region"]["rays"].get<int>(), small["region"]["rays"].get<int>());
  EXPECT_GT(big["region"]["nodes"].get<int>(), small["region"]["nodes"].get<int>());
  EXPECT_GT(big["region"]["prims"].get<int>(), small["region"]["prims"].get<int>());
  // 640×480 onto the 128-wide record: x 160..480 -> 32..96.
  EXPECT_EQ(big["region"]["x0"], 32);
  EXPECT_EQ(big["region"]["x1"], 96);

  const nlohmann::json c = read_json(path("click.json")), ray = read_json(path("ray.json"));
  ASSERT_FALSE(ray["hit"].is_null()) << "the middle pixel hits the teapot";
  EXPECT_TRUE(c["selected_is_leaf"].get<bool>()) << c["selected"];
  EXPECT_TRUE(c["region"].is_null()) << "a new selection replaces the region";
  const auto& p = c["selected_path"];
  ASSERT_GE(p.size(), 2u);
  EXPECT_EQ(p.front(), 0);
  EXPECT_EQ(p.back(), c["selected"]);
  // The leaf is one the clicked ray entered.
  bool entered = false;
  for (const auto& st : ray["steps"]) entered |= st["kind"] == "entered" && st["id"] == c["selected"];
  EXPECT_TRUE(entered) << c["selected"];
}

// A click's leaf selection is applied before the script's `wait` returns,
// follows the ray into the next structure shown (a grid: the cell the walk
// ended in, which holds the hit), and is dropped where the structure has
// nothing to select (brute force): the box view from before the click comes
// back instead of a node id that names something else there.
TEST_F(GuiScript, AClicksSelectionFollowsTheStructureShown) {
  const RunResult r = run(std::string("open ") + kTeapot + "\nsize 320 240\ncamera " + kCamera +
                          "\nset box-mode leaves\nwait\nclick 160 120\nwait\nscreenshot " + path("bvh.png").string() +
                          "\nstructure grid\nwait\nscreenshot " + path("grid.png").string() + "\ndump-ray " +
                          path("grid-ray.json").string() + "\nstructure brute\nwait\nscreenshot " +
                          path("brute.png").string() + "\nquit\n");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json bvh = read_json(path("bvh.json"))["options"];
  const nlohmann::json grid = read_json(path("grid.json"))["options"];
  const nlohmann::json brute = read_json(path("brute.json"))["options"];
  EXPECT_EQ(bvh["box-mode"], "subtree") << "the click's selection is in the picture taken after `wait`";
  EXPECT_EQ(grid["box-mode"], "subtree");
  const nlohmann::json ray = read_json(path("grid-ray.json"));
  ASSERT_FALSE(ray["hit"].is_null());
  std::string last_cell;
  for (const auto& st : ray["steps"])
    if (st["kind"] == "entered") last_cell = std::to_string(st["id"].get<std::uint64_t>());
  EXPECT_EQ(grid["box-node"], last_cell) << "the grid's selection is the cell its walk ended in";
  EXPECT_NE(grid["box-node"], bvh["box-node"]);
  EXPECT_EQ(brute["box-mode"], "leaves") << "nothing to select: the box view before the click";
}

// A box mode chosen while the next structure builds is the user's: the click's
// ray, cast again on the new build, no longer puts the view back to its leaf
// (it did: `box-mode depth` set before the grid was built was lost).
TEST_F(GuiScript, ABoxModeSetDuringARebuildIsNotOverriddenByTheClick) {
  const RunResult r = run(std::string("open ") + kTeapot + "\nsize 320 240\ncamera " + kCamera +
                          "\nwait\nclick 160 120\nwait\ndump-stats " + path("before.json").string() +
                          "\nstructure kdtree\nset box-mode depth\nwait\ndump-stats " + path("after.json").string() +
                          "\nscreenshot " + path("kd.png").string() + "\nquit\n");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(read_json(path("kd.json"))["options"]["box-mode"], "depth");
  EXPECT_EQ(read_json(path("after.json"))["structure"], "kdtree");
  EXPECT_GT(read_json(path("after.json"))["boxes"]["drawn"].get<int>(), 1) << "the depth's boxes, not one leaf";
}

// A node id typed into the subtree mode says what it names in the structure
// shown, and, once another build is shown, that it was set in an earlier one
// (node ids are per build) until an id is set again (the same one too).
TEST_F(GuiScript, ATypedNodeIdSaysWhatItNamesAndWhichBuildItWasSetIn) {
  const RunResult r =
      run(std::string("open ") + kTeapot + "\nsize 320 240\ncamera " + kCamera +
          "\nset box-mode subtree\nset box-node 5\nwait\ndump-stats " + path("bvh.json").string() +
          "\nstructure grid\nwait\ndump-stats " + path("grid.json").string() + "\nscreenshot " +
          path("grid-shot.png").string() + "\nset box-node 5\nwait\ndump-stats " + path("grid5.json").string() +
          "\nset box-node 7\nwait\ndump-stats " + path("grid7.json").string() +
          "\nset box-node 2000000000\nwait\ndump-stats " + path("past.json").string() +
          // Set again right after a switch, before the new build is shown: it is that build's.
          "\nstructure kdtree\nset box-node 5\nwait\ndump-stats " + path("kd.json").string() + "\nquit\n");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string bvh = read_json(path("bvh.json"))["boxes"]["node_note"];
  const std::string grid = read_json(path("grid.json"))["boxes"]["node_note"];
  const std::string grid5 = read_json(path("grid5.json"))["boxes"]["node_note"];
  const std::string grid7 = read_json(path("grid7.json"))["boxes"]["node_note"];
  const std::string past = read_json(path("past.json"))["boxes"]["node_note"];
  const std::string kd = read_json(path("kd.json"))["boxes"]["node_note"];
  EXPECT_EQ(kd.rfind("node 5: ", 0), 0u) << kd;
  EXPECT_EQ(kd.find("earlier build"), std::string::npos) << kd;
  EXPECT_EQ(bvh.rfind("node 5: ", 0), 0u) << bvh;
  EXPECT_EQ(bvh.find("earlier build"), std::string::npos) << bvh;
  EXPECT_EQ(grid.rfind("cell 5 (x ", 0), 0u) << grid;
  EXPECT_NE(grid.find("; the id was set in an earlier build (bvh"), std::string::npos) << grid;
  EXPECT_EQ(grid5.rfind("cell 5 (x ", 0), 0u) << grid5;
  EXPECT_EQ(grid5.find("earlier build"), std::string::npos) << "the same id set again names this build: " << grid5;
  EXPECT_EQ(grid7.rfind("cell 7 (x ", 0), 0u) << grid7;
  EXPECT_EQ(grid7.find("earlier build"), std::string::npos) << grid7;
  EXPECT_EQ(past.rfind("no cell 2000000000: this grid has cells 0-", 0), 0u) << past;
  const nlohmann::json shot = read_json(path("grid-shot.json"));
  EXPECT_EQ(shot["boxes"]["node_note"], grid) << "the side-car says which boxes the picture shows";
  EXPECT_NE(shot["caption"].get<std::string>().find(", boxes of " + grid), std::string::npos) << shot["caption"];
}

// The Tree's visit swatches share the 3D boxes' colour ramp while the boxes
// are drawn by visits: its top colour is the hottest box drawn (depth 4 here,
// cooler than the root), and the root's count when no boxes are shown.
TEST_F(GuiScript, TreeSwatchesShareTheBoxesVisitRamp) {
  const RunResult r =
      run(std::string("open ") + kTeapot + "\nsize 320 240\ncamera " + kCamera + "\nwait\ndump-insight " +
          path("insight.json").string() + "\nset boxes on\nset box-mode depth\nset box-depth 4\nwait\ndump-stats " +
          path("depth4.json").string() + "\nset boxes off\nwait\ndump-stats " + path("off.json").string() + "\nquit\n");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json in = read_json(path("insight.json"));
  const nlohmann::json d4 = read_json(path("depth4.json")), off = read_json(path("off.json"));
  const std::uint64_t root = in["hot"][0]["visits"].get<std::uint64_t>();
  ASSERT_EQ(in["hot"][0]["node"], 0);
  const std::uint64_t box_max = d4["boxes"]["visit_max"].get<std::uint64_t>();
  EXPECT_GT(d4["boxes"]["drawn"].get<int>(), 1);
  EXPECT_GT(box_max, 0u);
  EXPECT_LT(box_max, root) << "no box at depth 4 is entered by every ray the root is";
  EXPECT_TRUE(d4["tree"]["swatch_of_boxes"].get<bool>());
  EXPECT_EQ(d4["tree"]["swatch_max"].get<std::uint64_t>(), box_max);
  EXPECT_FALSE(off["tree"]["swatch_of_boxes"].get<bool>());
  EXPECT_EQ(off["tree"]["swatch_max"].get<std::uint64_t>(), root);
}

// select-region measures the view first when it must; that request is
// answered even when the measurement finished between two frames, so a later
// dump-insight measures the structure shown then (it wrote the grid's hot
// cells and node counts for brute force).
TEST_F(GuiScript, DumpInsightAfterSelectRegionMeasuresTheStructureShown) {
  // 160x120: brute force's heatmap tests every triangle for every pixel (at 320x240 most of the test's time).
  const RunResult r = run(std::string("open ") + kTeapot + "\nsize 160 120\ncamera " + kCamera +
                          "\nstructure grid\nwait\nselect-region 50 40 100 80\nstructure brute\nwait\n"
                          "dump-insight " +
                          path("brute.json").string() + "\nquit\n");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = read_json(path("brute.json"));
  EXPECT_TRUE(j["hot"].empty()) << "brute force has no nodes: " << j["hot"];
  for (const auto& [mode, m] : j["modes"].items()) EXPECT_EQ(m["nodes_per_ray"].get<double>(), 0.0) << mode;
}

// A/B from a script: A pinned with leaf size 1, B with leaf size 16 on the
// same view: B tests more primitives and enters fewer nodes. Then x-ray on
// (the heatmap's traversal toggle): the heatmap and B count more primitive
// tests than front-to-back with early termination.
TEST_F(GuiScript, ABFromAScriptAndTheHeatmapsXray) {
  const RunResult r = run(std::string("open ") + kTeapot + "\nsize 480 360\ncamera " + kCamera +
                          "\nset leaf 1\nset heatmap full\nwait\npin-a\nset leaf 16\nwait\n"
                          "dump-ab " +
                          path("leaf.json").string() + "\nwait\ndump-stats " + path("plain.json").string() +
                          "\npin-a\nset xray on\nwait\ndump-stats " + path("xray.json").string() + "\ndump-ab " +
                          path("xray-ab.json").string() + "\nquit\n");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json leaf = read_json(path("leaf.json"));
  EXPECT_NE(leaf["a"].get<std::string>().find("leaf 1"), std::string::npos) << leaf["a"];
  EXPECT_NE(leaf["b"].get<std::string>().find("leaf 16"), std::string::npos) << leaf["b"];
  EXPECT_GT(leaf["prims"]["total_b"].get<double>(), leaf["prims"]["total_a"].get<double>());
  EXPECT_LT(leaf["nodes"]["total_b"].get<double>(), leaf["nodes"]["total_a"].get<double>());
  EXPECT_GT(leaf["prims"]["pixels"].get<int>(), 0);
  // The leaf size changes the tree, not the closest hits; each side is timed.
  EXPECT_GT(leaf["hits_a"].get<int>(), 0);
  EXPECT_EQ(leaf["hits_b"], leaf["hits_a"]);
  EXPECT_EQ(leaf["hits_changed"].get<int>(), 0);
  EXPECT_GT(leaf["trace_ms_a"].get<double>(), 0.0);
  EXPECT_GT(leaf["trace_ms_b"].get<double>(), 0.0);

  const nlohmann::json plain = read_json(path("plain.json")), xray = read_json(path("xray.json"));
  // The A/B window shows the comparison dump-ab made (it stayed empty), in its metric (nodes).
  const nlohmann::json& window = plain["ab_window"];
  ASSERT_TRUE(window["shown"].get<bool>()) << window;
  EXPECT_EQ(window["a"], leaf["a"]);
  EXPECT_EQ(window["b"], leaf["b"]);
  EXPECT_EQ(window["metric"], "nodes");
  EXPECT_EQ(window["total_a"].get<double>(), leaf["nodes"]["total_a"].get<double>());
  EXPECT_EQ(window["total_b"].get<double>(), leaf["nodes"]["total_b"].get<double>());
  EXPECT_GT(xray["view"]["mean_prims"].get<double>(), plain["view"]["mean_prims"].get<double>());
  const nlohmann::json xab = read_json(path("xray-ab.json"));
  EXPECT_NE(xab["b"].get<std::string>().find("x-ray"), std::string::npos) << xab["b"];
  EXPECT_GT(xab["prims"]["total_b"].get<double>(), xab["prims"]["total_a"].get<double>());
}

// The GPU heatmap never freezes the window: with heatmap-gpu-ms 0 the
// compute shader traces one 8-row band per frame, so while the 160x120 image
// is in progress the window keeps drawing (the frame counter advances), the
// progress (rows done) grows, the previous CPU image stays up, and only the
// finished image is shown, with the CPU's counts.
TEST_F(GuiScript, GpuHeatmapTracesInBandsWhileTheWindowKeepsDrawing) {
  const std::string script = std::string("open ") + kTeapot + "\nsize 160 120\ncamera " + kCamera +
                             "\nset heatmap full\nset heatmap-gpu-ms 0\nwait\ndump-stats " + path("cpu.json").string() +
                             "\nset heatmap-gpu on\nframes 3\ndump-stats " + path("p1.json").string() +
                             "\nframes 3\ndump-stats " + path("p2.json").string() + "\nwait\ndump-stats " +
                             path("done.json").string() + "\nquit\n";
  const RunResult r = run(script);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json cpu = read_json(path("cpu.json")), p1 = read_json(path("p1.json")),
                       p2 = read_json(path("p2.json")), done = read_json(path("done.json"));
  ASSERT_TRUE(p1["gpu_trace"].is_object()) << p1["gpu_trace"] << " " << p1["view"]["gpu_note"];
  ASSERT_TRUE(p2["gpu_trace"].is_object()) << p2["gpu_trace"];
  const int rows1 = p1["gpu_trace"]["rows_done"], rows2 = p2["gpu_trace"]["rows_done"];
  EXPECT_EQ(p1["gpu_trace"]["rows"], 120);
  EXPECT_GT(rows1, 0);
  EXPECT_LT(rows2, 120);
  EXPECT_GT(rows2, rows1);  // progress between the dumps
  EXPECT_EQ(rows2 - rows1, 8 * (p2["gpu_trace"]["bands"].get<int>() - p1["gpu_trace"]["bands"].get<int>()));
  EXPECT_GE(p2["frames"].get<int>(), p1["frames"].get<int>() + 3);  // frames drawn mid-trace
  EXPECT_GT(done["frames"].get<int>(), p2["frames"].get<int>());
  // Mid-trace the CPU's image is still the one shown; then the GPU's, complete.
  EXPECT_EQ(p2["view"]["device"], "cpu");
  EXPECT_TRUE(done["gpu_trace"].is_null()) << done["gpu_trace"];
  const nlohmann::json& v = done["view"];
  EXPECT_EQ(v["device"], "gpu") << v["gpu_note"];
  EXPECT_EQ(v["complete"], true);
  EXPECT_EQ(v["rays"], 160 * 120);
  for (const char* k : {"hits", "mean_nodes", "max_nodes", "mean_prims", "max_prims", "mean_value", "max_value"})
    EXPECT_EQ(v[k], cpu["view"][k]) << k;
}

// View panel "Trace on: GPU" (`set heatmap-gpu on`): the BVH's heatmap is
// traced by the compute shader on the window's context (llvmpipe here) with
// the CPU worker's counts; another structure falls back to the CPU and says why.
TEST_F(GuiScript, HeatmapTracedOnTheGpuCountsWhatTheCpuCounts) {
  const std::string script = std::string("open ") + kTeapot + "\nsize 160 120\ncamera " + kCamera +
                             "\nset heatmap full\nwait\ndump-stats " + path("cpu.json").string() +
                             "\nset heatmap-gpu on\nwait\ndump-stats " + path("gpu.json").string() +
                             "\nstructure grid\nwait\ndump-stats " + path("grid.json").string() + "\nquit\n";
  const RunResult r = run(script);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json cpu = read_json(path("cpu.json"))["view"], gpu = read_json(path("gpu.json"))["view"];
  EXPECT_EQ(cpu["device"], "cpu");
  EXPECT_EQ(gpu["device"], "gpu") << gpu["gpu_note"];
  EXPECT_EQ(gpu["complete"], true);
  EXPECT_EQ(gpu["rays"], 160 * 120);
  EXPECT_GT(gpu["hits"].get<std::uint64_t>(), 0u);
  for (const char* k : {"hits", "mean_nodes", "max_nodes", "mean_prims", "max_prims", "mean_value", "max_value"})
    EXPECT_EQ(gpu[k], cpu[k]) << k;
  const nlohmann::json grid = read_json(path("grid.json"))["view"];
  EXPECT_EQ(grid["structure"], "grid");
  EXPECT_EQ(grid["device"], "cpu");
  EXPECT_EQ(grid["gpu_note"], "only the bvh structure is traced on the GPU");
  EXPECT_EQ(grid["complete"], true);
}

// reload-shaders rebuilds the GPU heatmap's trace too once it has been used:
// a broken trace_bvh.comp in the folder is named (and refused) then, not
// before; a good copy of it is taken and the view traced again on the GPU
// with the same counts (the BVH uploaded to the new tracer).
TEST_F(GuiScript, ReloadShadersRebuildsTheGpuTraceOnceItIsUsed) {
  fs::create_directories(path("broken"));
  std::ofstream(path("broken") / "trace_bvh.comp") << "#version 450 core\nvoid main( {\n";
  fs::create_directories(path("good"));
  fs::copy_file(fs::path(ACCELVIZ_SOURCE_DIR) / "shaders" / "trace_bvh.comp", path("good") / "trace_bvh.comp");
  const std::string head =
      std::string("open ") + kTeapot + "\nsize 160 120\ncamera " + kCamera + "\nset heatmap full\nwait\n";
  // Not used yet: nothing of the GPU trace to rebuild, so the broken file is not read.
  const RunResult unused = run(head + "reload-shaders " + path("broken").string() + "\nquit\n");
  EXPECT_EQ(unused.code, 0) << unused.err;
  const RunResult good =
      run(head + "set heatmap-gpu on\nwait\ndump-stats " + path("before.json").string() + "\nreload-shaders " +
          path("good").string() + "\nwait\ndump-stats " + path("after.json").string() + "\nquit\n");
  ASSERT_EQ(good.code, 0) << good.err;
  const nlohmann::json before = read_json(path("before.json"))["view"], after = read_json(path("after.json"))["view"];
  EXPECT_EQ(before["device"], "gpu") << before["gpu_note"];
  EXPECT_EQ(after["device"], "gpu") << after["gpu_note"];
  EXPECT_EQ(after["complete"], true);
  for (const char* k : {"hits", "mean_nodes", "max_nodes", "mean_prims", "max_prims"})
    EXPECT_EQ(after[k], before[k]) << k;
  const RunResult bad = run(head + "set heatmap-gpu on\nwait\nreload-shaders " + path("broken").string() + "\nquit\n");
  EXPECT_EQ(bad.code, 1);
  EXPECT_NE(bad.err.find((path("broken") / "trace_bvh.comp").string() + ":2:"), std::string::npos) << bad.err;
}

// Two-level views and the flatten what-if in the window: the `instances`
// metric counts instances per pixel, `flatten` predicts merging four trees
// and `flatten-commit` rebuilds the merged scene (three fewer instances);
// `dump-flatten` after it still writes the prediction, naming that scene.
TEST_F(GuiScript, InstancesMetricAndFlattenWhatIfCommit) {
  const RunResult r =
      run("open builtin:forest?size=1000&seed=4\nstructure tlas\nsize 320 240\nset metric instances\n"
          "wait\ndump-stats " +
          path("before.json").string() + "\nflatten 0-3\ndump-flatten " + path("what.json").string() +
          "\nflatten-commit\ndump-stats " + path("after.json").string() + "\ndump-flatten " +
          path("committed.json").string() + "\nquit\n");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json before = read_json(path("before.json"));
  EXPECT_EQ(before["view"]["metric"], "instances");
  EXPECT_GT(before["view"]["mean_instances"].get<double>(), 0.0);
  EXPECT_NEAR(before["view"]["mean_value"].get<double>(), before["view"]["mean_instances"].get<double>(), 1e-9);
  const double instances = before["build"]["extra"]["instances"].get<double>();
  const nlohmann::json what = read_json(path("what.json"));
  EXPECT_EQ(what["instances"], "0-3");
  EXPECT_EQ(what["merged_instances"].get<int>(), 4);
  EXPECT_GT(what["merged_triangles"].get<int>(), 0);
  EXPECT_EQ(what["two_level"]["instances"].get<double>(), instances);
  EXPECT_EQ(what["flattened"]["instances"].get<double>(), instances - 3);
  EXPECT_EQ(what["flattened"]["hits"], what["two_level"]["hits"]);
  EXPECT_GT(what["two_level"]["trace_ms"].get<double>(), 0.0);
  const nlohmann::json after = read_json(path("after.json"));
  EXPECT_NE(after["scene"].get<std::string>().find("[flattened 4 instances]"), std::string::npos) << after["scene"];
  EXPECT_EQ(after["build"]["extra"]["instances"].get<double>(), instances - 3);
  EXPECT_EQ(after["triangles"], before["triangles"]);
  // After the commit, dump-flatten still has the prediction, and names the scene it opened.
  nlohmann::json committed = read_json(path("committed.json"));
  EXPECT_EQ(committed["committed"], after["scene"]);
  committed.erase("committed");
  EXPECT_EQ(committed, what);
}

// A window ended by SIGTERM (a kill, a logout's SIGHUP, Ctrl-C) closes as its close button does: the
// settings and the layout are saved on the way out (imgui.ini is written only at exit in a run this
// short), and the status is 128 + 15. Killed outright, the changes since the last scene opened were lost.
TEST_F(GuiScript, ATerminatedWindowSavesItsSettingsAndLayout) {
  const fs::path config = dir_ / "interactive-config";
  const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
  const std::string cmd = "XDG_CONFIG_HOME='" + config.string() + "' timeout --preserve-status -s TERM 8 '" +
                          ACCELVIZ_BIN + "' 'builtin:teapot?size=300' > '" + out.string() + "' 2> '" + err.string() +
                          "'";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status)) << read_file(err);
  EXPECT_EQ(WEXITSTATUS(status), 128 + SIGTERM) << read_file(err);
  EXPECT_TRUE(fs::exists(config / "accelviz" / "imgui.ini")) << "the layout saved at exit; stderr: " << read_file(err);
  const nlohmann::json settings = read_json(config / "accelviz" / "settings.json");
  EXPECT_EQ(settings["last_scene"], "builtin:teapot?size=300");
}

// The Cost of accuracy window, scripted: `sweep` runs the panel's sweep on the shown scene and view,
// `dump-sweep` waits for it and writes its settings' figures as sweep.json's results hold them. The
// trees it builds are the CLI's: the same SAH cost, nodes, leaves and memory for every setting as
// `accelviz sweep` on the same scene (what is timed differs; what is built must not).
TEST_F(GuiScript, CostOfAccuracySweepBuildsWhatTheCommandLineBuilds) {
  const RunResult r =
      run("open " + std::string(kTeapot) + "\nstructure bvh\nsweep buckets=2,8 leaf=1,4\ndump-sweep " +
          path("gui.json").string() + "\nstructure grid\ndump-sweep " + path("again.json").string() + "\n");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json gui = read_json(path("gui.json"));
  EXPECT_EQ(gui["state"], "done");
  EXPECT_EQ(gui["structure"], "bvh");
  EXPECT_EQ(gui["triangles"], 2256);
  EXPECT_EQ(gui["rays"], 160 * 120);  // the panel's default ray size over the view
  EXPECT_EQ(gui["params"], nlohmann::json::parse(R"({"buckets": ["2", "8"], "leaf": ["1", "4"]})"));
  // What it started from: the scene, the view (as render --camera takes it), the structure's options.
  EXPECT_EQ(gui["scene"], kTeapot);
  const std::string camera = gui["camera"].get<std::string>();
  EXPECT_EQ(std::count(camera.begin(), camera.end(), ','), 6) << camera;
  EXPECT_EQ(gui["options"]["splitter"], "binned");
  EXPECT_EQ(gui["program"]["line"].get<std::string>().rfind("accelviz ", 0), 0u) << gui["program"];
  // A later dump-sweep writes the same sweep (a structure change starts none).
  nlohmann::json again = read_json(path("again.json"));
  EXPECT_EQ(again["results"].size(), gui["results"].size());

  const std::string cmd = std::string("'") + ACCELVIZ_BIN + "' -q sweep '" + kTeapot +
                          "' --param buckets=2,8 --param leaf=1,4 --size 32x24 --repeat 1 -j 1 --out '" +
                          path("cli").string() + "' > /dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const nlohmann::json cli = read_json(path("cli") / "sweep.json");
  ASSERT_EQ(gui["results"].size(), 4u);
  ASSERT_EQ(cli["results"].size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    const nlohmann::json &g = gui["results"][i], &c = cli["results"][i];
    EXPECT_EQ(g["label"], c["label"]);
    for (const char* key : {"sah_cost", "nodes", "leaves", "max_depth", "memory_bytes"})
      EXPECT_EQ(g[key], c[key]) << g["label"] << " " << key;
    EXPECT_GT(g["rays_per_s"].get<double>(), 0.0) << g["label"];
    EXPECT_GT(g["nodes_per_ray"].get<double>(), 0.0) << g["label"];
  }
  EXPECT_NE(gui["results"][0]["sah_cost"], gui["results"][2]["sah_cost"]) << "buckets=2 and 8 built the same tree";
}

// dump-sweep before any sweep is a script error naming the line, not a wait for ever.
TEST_F(GuiScript, DumpSweepWithoutASweepIsAnError) {
  const RunResult r = run("open " + std::string(kTeapot) + "\ndump-sweep " + path("none.json").string() + "\n");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(":2: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("no sweep run yet (use sweep PARAMS first)"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("none.json")));
}

// The Robustness window, scripted: `robustness N` runs its lab on the shown scene with the shown
// structure's own traversal as a row, `dump-robustness` writes what `accelviz robustness --json`
// prints for the same scene, structure and rays: every variant's misses, double hits and wrong hits.
TEST_F(GuiScript, RobustnessLabFindsWhatTheCommandLineFinds) {
  const RunResult r = run("open " + std::string(kTeapot) + "\nstructure kdtree\nrobustness 3000\ndump-robustness " +
                          path("lab.json").string() + "\n");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json gui = read_json(path("lab.json"));
  EXPECT_EQ(gui["state"], "done");
  EXPECT_EQ(gui["structure"], "kdtree");
  EXPECT_EQ(gui["rays"], 3000);
  const fs::path out = path("cli.json");
  const std::string cmd = std::string("'") + ACCELVIZ_BIN + "' -q robustness '" + kTeapot +
                          "' --structure kdtree --rays 3000 -j 1 --json > '" + out.string() + "'";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const nlohmann::json cli = read_json(out);
  EXPECT_EQ(gui["reference_hits"], cli["reference_hits"]);
  EXPECT_EQ(gui["rays_by_family"], cli["rays_by_family"]);
  ASSERT_EQ(gui["variants"].size(), cli["variants"].size());
  ASSERT_EQ(gui["variants"].size(), 6u);  // four lab variants and the K-D tree's two tests
  for (std::size_t i = 0; i < gui["variants"].size(); ++i) {
    const nlohmann::json &g = gui["variants"][i], &c = cli["variants"][i];
    EXPECT_EQ(g["name"], c["name"]);
    for (const char* key : {"misses", "double_hits", "wrong", "misses_by_family", "not_traced"})
      EXPECT_EQ(g[key], c[key]) << g["name"] << " " << key;
  }
  EXPECT_EQ(gui["variants"][3]["misses"], 0) << "watertight + padded slab missed";
  EXPECT_GT(gui["variants"][0]["misses"].get<int>(), 0) << "Moller-Trumbore missed nothing: the rays are not hard";
}

// `cancel sweep` is the Cost of accuracy window's Cancel: the sweep stops inside the setting being
// measured and keeps what was measured; `dump-sweep` then says `cancelled` with fewer results than
// settings. (24 settings over a 20,000-triangle teapot take seconds; the cancel comes a frame later.)
TEST_F(GuiScript, CancelStopsASweepAndKeepsWhatItMeasured) {
  const RunResult r =
      run("open builtin:teapot?size=20000\nsweep buckets=2,4,8,16,32,exact leaf=1,2,4,8\ncancel sweep\ndump-sweep " +
          path("cut.json").string() + "\n");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json cut = read_json(path("cut.json"));
  EXPECT_EQ(cut["state"], "cancelled");
  EXPECT_LT(cut["results"].size(), 24u);
}
