// The --script language: parsing (every command, comments, errors naming the
// file and line) and the runner's sequencing over a host that may need more
// frames, fails, or never finishes.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <functional>

#include "tests/support/temp_dir.h"
#include "ui/app/script.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_app_script {

using namespace accelviz;
using K = ScriptCommand::Kind;

namespace {

std::string parse_error(const std::string& text) {
  try {
    parse_script(text, "s.txt");
  } catch (const ScriptError& e) {
    return e.what();
  }
  return "(no error)";
}

/// Each script of `cases` fails to parse with a message starting with its expected text.
void expect_parse_errors(std::initializer_list<std::pair<const char*, const char*>> cases) {
  for (const auto& [text, expected] : cases) {
    const std::string e = parse_error(text);
    EXPECT_EQ(e.rfind(expected, 0), 0u) << "script: " << text << "\ngot: " << e;
  }
}

// A host that records commands and answers from a function.
struct FakeHost : ScriptHost {
  std::vector<std::string> log;
  std::function<Status(const ScriptCommand&)> answer = [](const ScriptCommand&) { return Status::done; };
  Status execute(const ScriptCommand& c) override {
    log.push_back(std::string(command_name(c.kind)) + (c.arg.empty() ? "" : " " + c.arg));
    return answer(c);
  }
};

}  // namespace

TEST(AppScript, ParsesEveryCommand) {
  const auto cmds = parse_script(
      "# a comment\n"
      "\n"
      "open builtin:teapot?size=2000\n"
      "  structure kdtree  \n"
      "set buckets 32\n"
      "set scale 0,40\n"
      "camera 6,4,8,0,1.2,0,40\n"
      "camera gltf:0\n"
      "size 640 480\n"
      "wait\n"
      "click 320 240\n"
      "step 3\n"
      "step next\n"
      "screenshot out dir/shot one.png\n"
      "dump-ray ray.json\n"
      "dump-stats stats.json\n"
      "quit\r\n",
      "s.txt");
  ASSERT_EQ(cmds.size(), 15u);
  EXPECT_EQ(cmds[0].kind, K::open);
  EXPECT_EQ(cmds[0].arg, "builtin:teapot?size=2000");
  EXPECT_EQ(cmds[0].line, 3);
  EXPECT_EQ(cmds[1].kind, K::structure);
  EXPECT_EQ(cmds[1].arg, "kdtree");
  EXPECT_EQ(cmds[2].kind, K::set);
  EXPECT_EQ(cmds[2].arg, "buckets");
  EXPECT_EQ(cmds[2].value, "32");
  EXPECT_EQ(cmds[3].value, "0,40");
  EXPECT_EQ(cmds[4].kind, K::camera);
  EXPECT_EQ(cmds[5].arg, "gltf:0");
  EXPECT_EQ(cmds[6].kind, K::size);
  EXPECT_EQ(cmds[6].x, 640);
  EXPECT_EQ(cmds[6].y, 480);
  EXPECT_EQ(cmds[7].kind, K::wait);
  EXPECT_EQ(cmds[8].kind, K::click);
  EXPECT_EQ(cmds[8].x, 320);
  EXPECT_EQ(cmds[9].arg, "3");
  EXPECT_EQ(cmds[10].arg, "next");
  EXPECT_EQ(cmds[11].kind, K::screenshot);
  EXPECT_EQ(cmds[11].arg, "out dir/shot one.png") << "paths keep their spaces";
  EXPECT_EQ(cmds[12].kind, K::dump_ray);
  EXPECT_EQ(cmds[13].kind, K::dump_stats);
  EXPECT_EQ(cmds[14].kind, K::quit);
  EXPECT_EQ(cmds[14].line, 17);
}

TEST(AppScript, ErrorsNameFileAndLine) {
  struct Case {
    const char* text;
    const char* expected;
  };
  for (const Case& c : {
           Case{"wait\nfrobnicate\n", "s.txt:2: unknown command 'frobnicate'"},
           Case{"open\n", "s.txt:1: open: expected a scene"},
           Case{"\n\nset buckets\n", "s.txt:3: set buckets: expected a value"},
           Case{"set bukets 4\n", "s.txt:1: set: unknown option 'bukets'"},
           Case{"set buckets 1\n", "s.txt:1: set buckets: expected an integer in 2..256, got '1'"},
           Case{"set leaf 8\nset leaf-cap 4\n", "s.txt:2: set leaf-cap: expected an integer in 8..255"},
           Case{"structure octopus\n", "s.txt:1: structure: expected one of"},
           Case{"size 640\n", "s.txt:1: size: expected W H"},
           Case{"size 10 10\n", "s.txt:1: size: W and H must lie in 64..8192"},
           Case{"click 1 2 3\n", "s.txt:1: click: expected X Y"},
           Case{"click -1 2\n", "s.txt:1: click: X and Y must be >= 0"},
           Case{"step sideways\n", "s.txt:1: step: expected N"},
           Case{"camera 1,2,3\n", "s.txt:1: camera: expected 6 or 7 numbers"},
           Case{"camera 1,2,3,1,2,3\n", "s.txt:1: camera: eye and target are the same point"},
           Case{"camera 0,0,5,0,0,0,180\n", "s.txt:1: camera: fov must lie strictly between 0 and 180"},
           Case{"camera gltf:x\n", "s.txt:1: camera: expected gltf:N"},
           Case{"wait now\n", "s.txt:1: wait: takes no argument"},
           Case{"quit please\n", "s.txt:1: quit: takes no argument"},
           Case{"screenshot out/figure.jpg\n",
                "s.txt:1: screenshot: out/figure.jpg: a PNG file's name must end in .png"},
           Case{"screenshot out/figure\n", "s.txt:1: screenshot: out/figure: a PNG file's name must end in .png"},
       }) {
    const std::string e = parse_error(c.text);
    EXPECT_EQ(e.rfind(c.expected, 0), 0u) << "script: " << c.text << "\ngot: " << e;
  }
  // Later lines are not checked against earlier ones' configuration only
  // when they come first: the cap is fine before the leaf grows.
  EXPECT_EQ(parse_error("set leaf-cap 32\nset leaf 8\n"), "(no error)");
  EXPECT_EQ(parse_error("screenshot out/Figure 1.PNG\n"), "(no error)");
}

TEST(AppScript, InsightRegionAndABCommands) {
  const auto cmds = parse_script(
      "select-region 10 20 30 5\npin-a\ndump-ab /tmp/ab out.json\nset xray on\n"
      "set back-to-front on\n",
      "s.txt");
  ASSERT_EQ(cmds.size(), 5u);
  EXPECT_EQ(cmds[0].kind, K::select_region);
  EXPECT_EQ(cmds[0].x, 10);
  EXPECT_EQ(cmds[0].y, 20);
  EXPECT_EQ(cmds[0].x2, 30);
  EXPECT_EQ(cmds[0].y2, 5);
  EXPECT_EQ(cmds[1].kind, K::pin_a);
  EXPECT_EQ(cmds[2].kind, K::dump_ab);
  EXPECT_EQ(cmds[2].arg, "/tmp/ab out.json");
  EXPECT_EQ(command_name(K::select_region), "select-region");
  expect_parse_errors({
      {"select-region 1 2 3\n", "s.txt:1: select-region: expected X0 Y0 X1 Y1"},
      {"select-region 1 2 3 4 5\n", "s.txt:1: select-region: expected X0 Y0 X1 Y1"},
      {"select-region 1 -2 3 4\n", "s.txt:1: select-region: expected X0 Y0 X1 Y1"},
      {"select-region 5 2 5 4\n", "s.txt:1: select-region: the rectangle is empty"},
      {"pin-a now\n", "s.txt:1: pin-a: takes no argument"},
      {"dump-ab\n", "s.txt:1: dump-ab: expected a file path"},
      {"set xray maybe\n", "s.txt:1: set xray: expected on or off"},
  });
}

// `window open|close TITLE`: a panel by its title (with spaces), checked
// when the script is read.
TEST(AppScript, WindowCommandNamesAPanel) {
  const auto cmds = parse_script("window open A/B compare\nwindow close Tree\n", "s.txt");
  ASSERT_EQ(cmds.size(), 2u);
  EXPECT_EQ(cmds[0].kind, K::window);
  EXPECT_EQ(cmds[0].value, "open");
  EXPECT_EQ(cmds[0].arg, "A/B compare");
  EXPECT_EQ(cmds[1].value, "close");
  EXPECT_EQ(cmds[1].arg, "Tree");
  EXPECT_EQ(command_name(K::window), "window");
  expect_parse_errors({
      {"window\n", "s.txt:1: window: expected open|close TITLE"},
      {"window show Tree\n", "s.txt:1: window: expected open|close TITLE"},
      {"window open\n", "s.txt:1: window: no panel titled '' (valid: Scene, Structure"},
      {"window open tree\n", "s.txt:1: window: no panel titled 'tree' (valid: Scene, Structure"},
  });
}

// `sweep PARAMS` is checked for the structure the script has chosen by then, as the Cost of
// accuracy panel's Run checks it; `dump-sweep PATH` takes the rest of the line.
TEST(AppScript, SweepCommandIsCheckedForTheStructureChosen) {
  const auto cmds =
      parse_script("sweep buckets=2,8 leaf=1,4\nstructure grid\nsweep lambda=1,4\ndump-sweep a b.json\n", "s.txt");
  ASSERT_EQ(cmds.size(), 4u);
  EXPECT_EQ(cmds[0].kind, K::sweep);
  EXPECT_EQ(cmds[0].arg, "buckets=2,8 leaf=1,4");
  EXPECT_EQ(cmds[2].arg, "lambda=1,4");
  EXPECT_EQ(cmds[3].kind, K::dump_sweep);
  EXPECT_EQ(cmds[3].arg, "a b.json");
  EXPECT_EQ(command_name(K::sweep), "sweep");
  EXPECT_EQ(command_name(K::dump_sweep), "dump-sweep");
  expect_parse_errors({
      {"sweep\n", "s.txt:1: sweep: expected parameters, e.g. buckets=2,8 leaf=1,4"},
      {"sweep buckets=abc\n", "s.txt:1: sweep: sweep parameter buckets: bad value 'abc'"},
      {"structure grid\nsweep buckets=2,8\n", "s.txt:2: sweep: "},
      {"structure tlas\nsweep triangle=fast,watertight\n",
       "s.txt:2: sweep: tlas is not swept (the sweep measures bvh, kdtree, grid, octree, voxels)"},
      {"dump-sweep\n", "s.txt:1: dump-sweep: expected a file path"},
  });
}

// `robustness [N]`: the Robustness window's ray count (its field's range) or none (the window's).
TEST(AppScript, RobustnessCommandTakesAnOptionalRayCount) {
  const auto cmds = parse_script("robustness\nrobustness 5000\ndump-robustness lab.json\n", "s.txt");
  ASSERT_EQ(cmds.size(), 3u);
  EXPECT_EQ(cmds[0].kind, K::robustness);
  EXPECT_EQ(cmds[0].x, 0);
  EXPECT_EQ(cmds[1].x, 5000);
  EXPECT_EQ(cmds[2].kind, K::dump_robustness);
  EXPECT_EQ(cmds[2].arg, "lab.json");
  EXPECT_EQ(command_name(K::dump_robustness), "dump-robustness");
  const char* const rays = "s.txt:1: robustness: expected N rays (an integer in 4..4194304) or nothing";
  expect_parse_errors({{"robustness 3\n", rays},
                       {"robustness 4194305\n", rays},
                       {"robustness many\n", rays},
                       {"robustness 10 20\n", rays}});
}

// `cancel build|sweep|robustness`: the Cancel button of one window.
TEST(AppScript, CancelNamesTheWorkItStops) {
  const auto cmds = parse_script("cancel build\ncancel sweep\ncancel robustness\n", "s.txt");
  ASSERT_EQ(cmds.size(), 3u);
  EXPECT_EQ(cmds[0].kind, K::cancel);
  EXPECT_EQ(cmds[0].arg, "build");
  EXPECT_EQ(cmds[2].arg, "robustness");
  const char* const which = "s.txt:1: cancel: expected build, sweep or robustness";
  expect_parse_errors({{"cancel\n", which}, {"cancel all\n", which}, {"cancel sweep now\n", which}});
}

// `frames N` lets N frames draw (the GPU heatmap test watches a trace
// progress across frames with it).
TEST(AppScript, FramesCommandTakesACount) {
  const auto cmds = parse_script("frames 3\nframes 100000\n", "s.txt");
  ASSERT_EQ(cmds.size(), 2u);
  EXPECT_EQ(cmds[0].kind, K::frames);
  EXPECT_EQ(cmds[0].x, 3);
  EXPECT_EQ(cmds[1].x, 100000);
  EXPECT_EQ(command_name(K::frames), "frames");
  for (const char* text : {"frames\n", "frames 0\n", "frames -2\n", "frames 100001\n", "frames two\n"}) {
    const std::string e = parse_error(text);
    EXPECT_EQ(e.rfind("s.txt:1: frames: expected N (an integer in 1..100000)", 0), 0u) << text << "\ngot: " << e;
  }
}

TEST(AppScript, MissingFileIsAnError) {
  try {
    load_script("/nonexistent/dir/script.txt");
    FAIL() << "no error";
  } catch (const ScriptError& e) {
    EXPECT_STREQ(e.what(), "/nonexistent/dir/script.txt:0: cannot be read: no such file");
  }
}

// Odd bytes: a NUL ended the message ("unknown command 'si"), a 10 MB
// argument was echoed whole, a byte order mark made the first command unknown.
TEST(AppScript, OddBytesGiveOneShortLine) {
  try {
    parse_script(std::string("size 320 240\nsi\0ze 320 240\n", 27), "nul.txt");
    ADD_FAILURE() << "no error";
  } catch (const ScriptError& e) {
    EXPECT_EQ(std::string(e.what()).substr(0, 36), "nul.txt:2: unknown command 'si?ze' (") << e.what();
    // Every command is listed, the last too (the 300-character cut ended it at "windo...").
    EXPECT_TRUE(std::string(e.what()).ends_with(", " + std::string(script_command_names().back()) + ")")) << e.what();
  }
  try {
    parse_script(std::string(100'000, 'x') + "\n", "word.txt");  // a long unknown word: cut, the list kept
    ADD_FAILURE() << "no error";
  } catch (const ScriptError& e) {
    EXPECT_NE(std::string(e.what()).find("'" + std::string(40, 'x') + "...' (valid: "), std::string::npos) << e.what();
    EXPECT_TRUE(std::string(e.what()).ends_with(")")) << e.what();
  }
  try {
    parse_script("set buckets " + std::string(10'000'000, '9') + "\n", "long.txt");
    ADD_FAILURE() << "no error";
  } catch (const ScriptError& e) {
    EXPECT_LE(std::string(e.what()).size(), 600u);
    EXPECT_TRUE(std::string(e.what()).ends_with("...")) << e.what();
  }
  const auto cmds = parse_script("\xEF\xBB\xBFopen builtin:teapot\nquit\n", "bom.txt");
  ASSERT_EQ(cmds.size(), 2u);
  EXPECT_EQ(cmds[0].kind, ScriptCommand::Kind::open);
  EXPECT_EQ(cmds[0].arg, "builtin:teapot");
}

// A folder ran as an empty script (exit 0, nothing said); a FIFO would block.
TEST(AppScript, AFolderOrAFifoIsNotAScript) {
  const test_support::TempDir tmp("script-kinds");
  const std::filesystem::path& dir = tmp.path();
  std::filesystem::create_directories(dir / "dir.txt");
  ASSERT_EQ(::mkfifo((dir / "fifo.txt").c_str(), 0644), 0);
  for (const char* name : {"dir.txt", "fifo.txt"}) {
    try {
      load_script(dir / name);
      ADD_FAILURE() << name << " was read as a script";
    } catch (const ScriptError& e) {
      EXPECT_NE(std::string(e.what()).find(":0: cannot be read: is "), std::string::npos) << e.what();
    }
  }
}

TEST(AppScript, RunnerRetriesCommandsThatNeedMoreFrames) {
  const auto cmds = parse_script("open a.glb\nwait\nclick 1 1\nquit\nclick 2 2\n", "s.txt");
  ScriptRunner runner(cmds, "s.txt");
  FakeHost host;
  int waits = 0;
  host.answer = [&](const ScriptCommand& c) {
    if (c.kind == K::wait && ++waits < 3) return ScriptHost::Status::again;
    return ScriptHost::Status::done;
  };
  EXPECT_EQ(runner.advance(host, 0.0), ScriptRunner::State::running);
  EXPECT_EQ(host.log, (std::vector<std::string>{"open a.glb", "wait"}));
  EXPECT_EQ(runner.advance(host, 1.0), ScriptRunner::State::running);
  EXPECT_EQ(runner.advance(host, 2.0), ScriptRunner::State::finished);
  // quit ends the script: the command after it never runs.
  EXPECT_EQ(host.log, (std::vector<std::string>{"open a.glb", "wait", "wait", "wait", "click", "quit"}));
  EXPECT_EQ(runner.advance(host, 3.0), ScriptRunner::State::finished);
}

TEST(AppScript, EndOfFileFinishes) {
  ScriptRunner runner(parse_script("wait\n", "s.txt"), "s.txt");
  FakeHost host;
  EXPECT_EQ(runner.advance(host, 0.0), ScriptRunner::State::finished);
  ScriptRunner empty({}, "e.txt");
  EXPECT_EQ(empty.advance(host, 0.0), ScriptRunner::State::finished);
}

TEST(AppScript, AFailingCommandNamesItsLine) {
  ScriptRunner runner(parse_script("wait\n\nclick 5 5\nquit\n", "s.txt"), "s.txt");
  FakeHost host;
  host.answer = [](const ScriptCommand& c) -> ScriptHost::Status {
    if (c.kind == K::click) throw std::runtime_error("pixel 5,5 is outside\nthe view");
    return ScriptHost::Status::done;
  };
  EXPECT_EQ(runner.advance(host, 0.0), ScriptRunner::State::failed);
  EXPECT_EQ(runner.error(), "s.txt:3: click: pixel 5,5 is outside the view");
  EXPECT_EQ(host.log.back(), "click");
}

TEST(AppScript, ACommandThatNeverCompletesTimesOut) {
  ScriptRunner runner(parse_script("wait\n", "s.txt"), "s.txt", /*timeout_s=*/10.0);
  FakeHost host;
  host.answer = [](const ScriptCommand&) { return ScriptHost::Status::again; };
  EXPECT_EQ(runner.advance(host, 100.0), ScriptRunner::State::running);
  EXPECT_EQ(runner.advance(host, 109.0), ScriptRunner::State::running);
  EXPECT_EQ(runner.advance(host, 110.5), ScriptRunner::State::failed);
  EXPECT_EQ(runner.error(), "s.txt:1: wait: not complete after 10 s");
}
}  // namespace unity_test_app_script
