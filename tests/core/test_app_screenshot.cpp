// Screenshot files: unique time-stamped names that never overwrite, the
// caption strip, and the JSON side-car with what reproduces the picture.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "core/query/camera.h"
#include "tests/support/temp_dir.h"
#include "ui/app/screenshot_files.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_app_screenshot {

using namespace accelviz;
namespace fs = std::filesystem;

namespace {

using test_support::read_file;
using test_support::TempDir;

RgbImage test_frame(int w, int h) {
  RgbImage img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      img.set(x, y, glm::u8vec3(static_cast<std::uint8_t>(x * 3), static_cast<std::uint8_t>(y * 5), 77));
  return img;
}

ScreenshotInfo test_info() {
  ScreenshotInfo info;
  info.scene = "builtin:teapot?size=2000";
  info.triangles = 2256;
  info.camera_spec = "6,4,8,0,1.2,0,40";
  info.camera = look_at({6, 4, 8}, {0, 1.2f, 0}, 40.0f * 3.14159265f / 180.0f);
  info.width = 64;
  info.height = 48;
  EXPECT_EQ(apply_option(info.config, "heatmap", "blend"), "");
  EXPECT_EQ(apply_option(info.config, "metric", "prims"), "");
  EXPECT_EQ(apply_option(info.config, "colormap", "inferno"), "");
  EXPECT_EQ(apply_option(info.config, "buckets", "8"), "");
  EXPECT_EQ(apply_option(info.config, "msaa", "1"), "");  // as render --view raster draws (its own test below)
  info.scale_min = 0.0f;
  info.scale_max = 39.0f;
  info.ray_pixel = std::make_pair(32, 24);
  info.ray_camera = info.camera;  // clicked in the view shown
  return info;
}

}  // namespace

TEST(AppScreenshot, NamesAreTimeStampedAndSkipTakenStems) {
  TempDir dir("shots");
  const std::time_t t = 1700000000;
  const std::string stamp = screenshot_timestamp(t);
  ASSERT_EQ(stamp.size(), 15u);  // YYYYmmdd-HHMMSS
  EXPECT_EQ(stamp[8], '-');
  ScreenshotPaths p = unique_screenshot_paths(dir.path(), stamp);
  EXPECT_EQ(p.png, dir.path() / ("accelviz-" + stamp + ".png"));
  EXPECT_EQ(p.json, dir.path() / ("accelviz-" + stamp + ".json"));
  std::ofstream(p.png) << "x";
  EXPECT_EQ(unique_screenshot_paths(dir.path(), stamp).png, dir.path() / ("accelviz-" + stamp + "-2.png"));
  // A side-car alone also takes the stem: the pair stays together.
  std::ofstream(dir.path() / ("accelviz-" + stamp + "-2.json")) << "{}";
  EXPECT_EQ(unique_screenshot_paths(dir.path(), stamp).png, dir.path() / ("accelviz-" + stamp + "-3.png"));
  // A dangling symbolic link takes its name too: the write refuses it, and save_screenshot retried the
  // same name 1,000 times (70 s on the window's thread) before "no free screenshot name".
  std::filesystem::create_symlink("/nonexistent/accelviz-test", dir.path() / ("accelviz-" + stamp + "-3.png"));
  EXPECT_EQ(unique_screenshot_paths(dir.path(), stamp).png, dir.path() / ("accelviz-" + stamp + "-4.png"));
  const RgbImage frame(4, 2, {128, 128, 128});
  ScreenshotInfo info;
  const SavedScreenshot saved = save_screenshot(dir.path(), frame, info, t);
  EXPECT_TRUE(saved.ok) << saved.error;
  EXPECT_EQ(saved.png, dir.path() / ("accelviz-" + stamp + "-4.png"));
}

TEST(AppScreenshot, SavingTwiceInTheSameSecondNeverOverwrites) {
  TempDir dir("shots");
  const fs::path folder = dir.path() / "created" / "on demand";
  const std::time_t t = 1700000000;
  const SavedScreenshot a = save_screenshot(folder, test_frame(64, 48), test_info(), t);
  ASSERT_TRUE(a.ok) << a.error;
  const std::string first_png = read_file(a.png), first_json = read_file(a.json);
  const SavedScreenshot b = save_screenshot(folder, test_frame(64, 48), test_info(), t);
  ASSERT_TRUE(b.ok) << b.error;
  EXPECT_NE(a.png, b.png);
  EXPECT_NE(a.json, b.json);
  EXPECT_EQ(read_file(a.png), first_png) << "the first picture is untouched";
  EXPECT_EQ(read_file(a.json), first_json);
  EXPECT_EQ(b.png.stem().string(), a.png.stem().string() + "-2");
}

// The PNG and its side-car are written both or neither: a side-car that cannot be written (here its
// name is one byte over the file system's 255, the PNG's fits) left the PNG behind, and a script's
// rerun was then refused by it.
TEST(AppScreenshot, APictureWhoseSideCarFailsLeavesNothing) {
  TempDir dir("shots");
  const fs::path png = dir.path() / (std::string(251, 'x') + ".png");  // 255 bytes; the .json 256
  const SavedScreenshot r = save_screenshot_as(png, test_frame(16, 8), test_info());
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find(std::string(251, 'x') + ".json"), std::string::npos) << r.error;
  EXPECT_FALSE(fs::exists(png)) << "no PNG without its side-car";
  EXPECT_TRUE(fs::is_empty(dir.path())) << "no temporary left";
}

TEST(AppScreenshot, ExplicitPathRefusesExistingFiles) {
  TempDir dir("shots");
  const fs::path png = dir.path() / "figure.png";
  const SavedScreenshot a = save_screenshot_as(png, test_frame(64, 48), test_info());
  ASSERT_TRUE(a.ok) << a.error;
  EXPECT_EQ(a.json, dir.path() / "figure.json");
  const std::string before = read_file(png);
  const SavedScreenshot b = save_screenshot_as(png, test_frame(32, 32), test_info());
  EXPECT_FALSE(b.ok);
  EXPECT_EQ(b.error, png.string() + ": exists (not overwritten)");
  EXPECT_EQ(read_file(png), before);
  // The side-car is checked too, before anything is written.
  fs::remove(png);
  const SavedScreenshot c = save_screenshot_as(png, test_frame(64, 48), test_info());
  EXPECT_FALSE(c.ok);
  EXPECT_EQ(c.error, (dir.path() / "figure.json").string() + ": exists (not overwritten)");
  EXPECT_FALSE(fs::exists(png));
  EXPECT_FALSE(save_screenshot_as(dir.path() / "no" / "such" / "dir.png", test_frame(8, 8), test_info()).ok);
}

TEST(AppScreenshot, CaptionStripUnderTheFrame) {
  const RgbImage frame = test_frame(200, 40);
  const RgbImage out = add_caption(frame, "BVH (Buckets=8) heatmap nodes");
  ASSERT_EQ(out.width, 200);
  ASSERT_GT(out.height, 40);
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 200; ++x) ASSERT_EQ(out.at(x, y), frame.at(x, y));
  // Text pixels (bright) and background pixels (dark) in the strip.
  int bright = 0, dark = 0;
  for (int y = 40; y < out.height; ++y)
    for (int x = 0; x < 200; ++x) (out.at(x, y).x > 150 ? bright : dark)++;
  EXPECT_GT(bright, 50);
  EXPECT_GT(dark, bright);
  // Capitals and the signs a caption uses are drawn as themselves.
  EXPECT_NE(add_caption(frame, "BVH").pixels, add_caption(frame, "bvh").pixels);
  EXPECT_NE(add_caption(frame, "a;b").pixels, add_caption(frame, "a b").pixels);
  EXPECT_NE(add_caption(frame, "region's").pixels, add_caption(frame, "region s").pixels);
}

TEST(AppScreenshot, LongCaptionsWrapInsteadOfBeingCut) {
  using V = std::vector<std::string>;
  EXPECT_EQ(wrap_caption("bvh (buckets=8), watertight", 40, 4), V{"bvh (buckets=8), watertight"});
  EXPECT_EQ(wrap_caption("bvh (buckets=8), watertight, heatmap nodes", 20, 4),
            (V{"bvh (buckets=8),", "watertight, heatmap", "nodes"}));
  EXPECT_EQ(wrap_caption("abcdefghij", 4, 4), (V{"abcd", "efgh", "ij"})) << "no space: broken mid-word";
  EXPECT_EQ(wrap_caption("aa bb cc dd ee ff", 5, 2), (V{"aa bb", "cc .."})) << "the last line says it goes on";
  EXPECT_TRUE(wrap_caption("", 10, 4).empty());

  // On the picture: one strip line per caption line, every line drawn.
  const RgbImage frame = test_frame(200, 40);
  const std::string caption = "bvh (splitter=binned, buckets=32, leaf=4, leaf-cap=16), watertight, heatmap nodes";
  const RgbImage one = add_caption(frame, "bvh");
  const RgbImage wrapped = add_caption(frame, caption);
  const int lines = static_cast<int>(wrap_caption(caption, (200 - 8) / 6, kCaptionMaxLines).size());
  ASSERT_GE(lines, 2);
  ASSERT_LE(lines, kCaptionMaxLines);
  EXPECT_EQ(wrapped.height - one.height, (lines - 1) * 10);
  for (int line = 0; line < lines; ++line) {
    int bright = 0;
    for (int y = 40 + 4 + line * 10; y < 40 + 4 + line * 10 + 7; ++y)
      for (int x = 0; x < 200; ++x) bright += wrapped.at(x, y).x > 150;
    EXPECT_GT(bright, 20) << "line " << line;
  }
}

TEST(AppScreenshot, SideCarSaysHowToReproduceThePicture) {
  const ScreenshotInfo info = test_info();
  const nlohmann::json j = screenshot_sidecar(info, "/x/accelviz-1.png");
  EXPECT_EQ(j["png"], "/x/accelviz-1.png");
  EXPECT_FALSE(j.contains("program"));  // the GUI sets it (the CLI's program record); left out when unknown
  ScreenshotInfo named = info;
  named.program = {{"commit", "abc"}, {"line", "accelviz 0.1.0 (commit abc, Release build)"}};
  EXPECT_EQ(screenshot_sidecar(named, "/x/accelviz-1.png")["program"], named.program);
  EXPECT_EQ(j["scene"], "builtin:teapot?size=2000");
  EXPECT_EQ(j["triangles"], 2256);
  EXPECT_EQ(j["size"]["width"], 64);
  EXPECT_EQ(j["camera"]["spec"], "6,4,8,0,1.2,0,40");
  EXPECT_NEAR(j["camera"]["yfov_deg"].get<double>(), 40.0, 1e-4);
  EXPECT_EQ(j["structure"]["name"], "bvh");
  EXPECT_EQ(j["structure"]["options"]["buckets"], "8");
  EXPECT_EQ(j["query"]["triangle_test"], "watertight");
  EXPECT_EQ(j["heatmap"]["display"], "blend");
  EXPECT_EQ(j["heatmap"]["metric"], "prims");
  EXPECT_EQ(j["heatmap"]["colormap"], "inferno");
  EXPECT_EQ(j["heatmap"]["scale"], "auto");
  EXPECT_EQ(j["heatmap"]["range"][1], 39.0);
  EXPECT_EQ(j["options"].size(), option_table().size());
  EXPECT_EQ(j["ray_pixel"][0], 32);
  EXPECT_EQ(j["caption"], info.scene + ", " + screenshot_caption(info.config) + ", ray of pixel 32,24");
  EXPECT_EQ(j["boxes"]["drawn"], 0);

  const std::string cmd = j["reproduce"]["render_heatmap"];
  for (const char* part :
       {"accelviz render 'builtin:teapot?size=2000'", "--structure bvh", "--camera 6,4,8,0,1.2,0,40", "--size 64x48",
        "--metric prims", "--colormap inferno", "--buckets 8", "--out accelviz-1-heatmap.png"})
    EXPECT_NE(cmd.find(part), std::string::npos) << part << " not in " << cmd;
  EXPECT_EQ(cmd.find("--max"), std::string::npos) << "auto scale: no --max";
  const std::string raster = j["reproduce"]["render_raster"];
  for (const char* part : {"--view raster", "--depth 3", "--blend 0.6", "--ray-pixel 32,24"})
    EXPECT_NE(raster.find(part), std::string::npos) << part << " not in " << raster;

  const auto& script = j["reproduce"]["script"];
  EXPECT_EQ(script.front(), "open builtin:teapot?size=2000");
  EXPECT_NE(std::find(script.begin(), script.end(), "set buckets 8"), script.end());
  EXPECT_NE(std::find(script.begin(), script.end(), "camera 6,4,8,0,1.2,0,40"), script.end());
  EXPECT_NE(std::find(script.begin(), script.end(), "click 32 24"), script.end());
  EXPECT_EQ(script.back(), "quit");
  EXPECT_TRUE(j["reproduce"]["notes"].empty());
}

// A ray clicked in one view and shown from another (the camera moved after
// the click): the replay set the new camera and then clicked, casting another
// ray (another triangle hit); it now clicks from the view of the click first,
// and the raster command casts the ray from that camera (--ray-camera).
TEST(AppScreenshot, ARayClickedInAnEarlierViewIsCastFromThatView) {
  ScreenshotInfo info = test_info();
  const Camera clicked_in = info.camera;
  info.camera_spec = "12,3,-2,0,1,0,45";
  info.camera = look_at({12, 3, -2}, {0, 1, 0}, 45.0f * 3.14159265f / 180.0f);
  info.ray_camera = clicked_in;
  const nlohmann::json j = screenshot_sidecar(info, "shot.png");
  const std::string ray_spec = explicit_camera_spec(clicked_in);
  EXPECT_EQ(j["ray_camera"], ray_spec);
  EXPECT_NE(j["caption"].get<std::string>().find("ray of pixel 32,24 of an earlier view"), std::string::npos)
      << j["caption"];
  std::vector<std::string> script = j["reproduce"]["script"];
  const auto at = [&](const std::string& line) {
    return std::find(script.begin(), script.end(), line) - script.begin();
  };
  ASSERT_LT(at("click 32 24"), static_cast<long>(script.size()));
  EXPECT_LT(at("camera " + ray_spec), at("click 32 24"));
  EXPECT_GT(at("camera 12,3,-2,0,1,0,45"), at("click 32 24"));
  const std::string raster = j["reproduce"]["render_raster"];
  EXPECT_NE(raster.find("--ray-camera " + ray_spec), std::string::npos) << raster;
  EXPECT_NE(raster.find("--camera 12,3,-2,0,1,0,45"), std::string::npos) << raster;
  // The spec reproduces the camera's ray.
  const Camera back = camera_from_spec(ray_spec, Scene{}, 4.0f / 3.0f);
  const Ray a = primary_ray(clicked_in, 32, 24, 64, 48), b = primary_ray(back, 32, 24, 64, 48);
  EXPECT_LT(glm::length(a.origin - b.origin), 1e-4f);
  EXPECT_LT(glm::length(a.direction - b.direction), 1e-4f);
  // Clicked in the view shown: no --ray-camera, the click after the camera as before.
  const nlohmann::json same = screenshot_sidecar(test_info(), "shot.png");
  EXPECT_TRUE(same["ray_camera"].is_null());
  EXPECT_EQ(same["reproduce"]["render_raster"].get<std::string>().find("--ray-camera"), std::string::npos);
}

// The traversal's order and x-ray are render options: the commands carry
// them (they were left out, and "unordered is not an option of render" noted:
// the command then counted another traversal than the picture's).
TEST(AppScreenshot, TheCommandsCarryTheTraversalOrderAndXray) {
  ScreenshotInfo info = test_info();
  QueryOptions& q = info.config.structure.query;
  q.back_to_front = true;
  q.xray = true;
  nlohmann::json j = screenshot_sidecar(info, "shot.png");
  for (const char* which : {"render_heatmap", "render_raster"}) {
    const std::string cmd = j["reproduce"][which];
    EXPECT_NE(cmd.find(" --order back-to-front"), std::string::npos) << cmd;
    EXPECT_NE(cmd.find(" --xray"), std::string::npos) << cmd;
  }
  EXPECT_EQ(j["query"]["back_to_front"], true);
  EXPECT_EQ(j["query"]["xray"], true);
  EXPECT_TRUE(j["reproduce"]["notes"].empty()) << j["reproduce"]["notes"];
  q = QueryOptions{};
  q.ordered = false;
  j = screenshot_sidecar(info, "shot.png");
  const std::string cmd = j["reproduce"]["render_heatmap"];
  EXPECT_NE(cmd.find(" --order unordered"), std::string::npos) << cmd;
  EXPECT_EQ(cmd.find(" --xray"), std::string::npos) << cmd;
}

// The audit: a grid screenshot's side-car listed each note twice (the heatmap's and the raster's
// commands both added the shared ones), and a default screenshot's raster command drew without the
// window's multisampling and did not say so.
TEST(AppScreenshot, NotesComeOnceAndNameTheWindowsMultisampling) {
  ScreenshotInfo info = test_info();
  info.config.structure.name = "grid";
  EXPECT_EQ(apply_option(info.config, "grid-res", "8,8,8"), "");
  info.config.view.auto_scale = false;
  info.config.view.scale_min = 5.0f;
  nlohmann::json notes = screenshot_sidecar(info, "shot.png")["reproduce"]["notes"];
  ASSERT_EQ(notes.size(), 2u) << notes;
  EXPECT_NE(notes[0].get<std::string>().find("the heatmap range starts at 5"), std::string::npos) << notes;
  EXPECT_NE(notes[1].get<std::string>().find("grid-res=8,8,8"), std::string::npos) << notes;
  EXPECT_EQ(apply_option(info.config, "msaa", "4"), "");
  notes = screenshot_sidecar(info, "shot.png")["reproduce"]["notes"];
  ASSERT_EQ(notes.size(), 3u) << notes;
  EXPECT_NE(notes[2].get<std::string>().find("4x multisampling"), std::string::npos) << notes;
}

// The whole caption rides in the PNG (the strip cuts it on a small window), with the build.
TEST(AppScreenshot, ThePngCarriesTheWholeCaptionAndTheProgram) {
  TempDir dir("shots");
  ScreenshotInfo info = test_info();
  info.program = {{"commit", "abc"}, {"line", "accelviz 0.1.0 (commit abc, Release build)"}};
  const SavedScreenshot saved = save_screenshot(dir.path(), test_frame(64, 48), info, std::time_t(1700000000));
  ASSERT_TRUE(saved.ok) << saved.error;
  std::ifstream in(saved.png, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::vector<PngText> text = png_text(bytes);
  ASSERT_EQ(text.size(), 2u);
  EXPECT_EQ(text[0].keyword, "Description");
  EXPECT_EQ(text[0].text, screenshot_caption(info));
  EXPECT_EQ(text[1].keyword, "Software");
  EXPECT_EQ(text[1].text, "accelviz 0.1.0 (commit abc, Release build)");
}

// A depth range whose last depth is below the first (a script or settings
// file can set one) draws the first depth alone; the replay command says
// that range, not one the CLI would refuse.
TEST(AppScreenshot, ADepthRangeBelowItsFirstDepthReplaysWhatWasDrawn) {
  ScreenshotInfo info = test_info();
  ViewSettings& v = info.config.view;
  v.show_boxes = true;
  v.box_mode = BoxMode::depth_range;
  v.box_depth = 5;
  v.box_depth_last = 2;
  EXPECT_EQ(v.box_range_last(), 5);
  std::string cmd = screenshot_sidecar(info, "shot.png")["reproduce"]["render_raster"];
  EXPECT_NE(cmd.find(" --depth 5 --depth-last 5"), std::string::npos) << cmd;
  v.box_depth_last = 7;
  EXPECT_EQ(v.box_range_last(), 7);
  cmd = screenshot_sidecar(info, "shot.png")["reproduce"]["render_raster"];
  EXPECT_NE(cmd.find(" --depth 5 --depth-last 7"), std::string::npos) << cmd;
}

// render --view raster draws a BVH's boxes only: for another structure the
// replay command leaves the window's boxes out and says so (it gave
// --depth, which the CLI refuses for them).
TEST(AppScreenshot, BoxesOfOtherStructuresThanTheBvhAreNotedNotReplayed) {
  ScreenshotInfo info = test_info();
  info.config.view.show_boxes = true;
  info.config.view.box_mode = BoxMode::depth;
  info.config.structure.name = "grid";
  EXPECT_TRUE(screenshot_sidecar(info, "shot.png")["reproduce"]["notes"].empty()) << "no box drawn, none left out";
  info.boxes_drawn = info.boxes_matched = 12;
  for (const char* name : {"kdtree", "grid", "octree", "voxels", "tlas"}) {
    SCOPED_TRACE(name);
    info.config.structure.name = name;
    const nlohmann::json j = screenshot_sidecar(info, "shot.png");
    const std::string cmd = j["reproduce"]["render_raster"];
    EXPECT_EQ(cmd.find(" --depth"), std::string::npos) << cmd;
    EXPECT_EQ(cmd.find(" --leaves"), std::string::npos) << cmd;
    EXPECT_NE(j["reproduce"]["notes"].dump().find("draws a BVH's node boxes only"), std::string::npos)
        << j["reproduce"]["notes"];
  }
  info.config.structure.name = "bvh";
  const std::string cmd = screenshot_sidecar(info, "shot.png")["reproduce"]["render_raster"];
  EXPECT_NE(cmd.find(" --depth 3"), std::string::npos) << cmd;
}

// A ray replay stopped before its end is brought back by the side-car's
// script (`step N` after the click), said on the caption, and noted for the
// raster command (which draws the whole traversal).
TEST(AppScreenshot, ARayReplayStepIsReplayedAndSaid) {
  ScreenshotInfo info = test_info();
  info.config.view.show_ray_path = true;
  info.ray_steps = 10;
  nlohmann::json j = screenshot_sidecar(info, "shot.png");
  std::string script = j["reproduce"]["script"].dump();
  EXPECT_EQ(script.find("\"step "), std::string::npos) << script;  // the whole traversal: no step
  EXPECT_NE(screenshot_caption(info).find(", ray of pixel 32,24"), std::string::npos) << screenshot_caption(info);
  EXPECT_EQ(screenshot_caption(info).find(" at step"), std::string::npos) << screenshot_caption(info);
  info.ray_step = 3;
  j = screenshot_sidecar(info, "shot.png");
  script = j["reproduce"]["script"].dump();
  EXPECT_NE(script.find("\"click 32 24\",\"step 3\",\"screenshot "), std::string::npos) << script;
  EXPECT_NE(screenshot_caption(info).find(", ray of pixel 32,24 at step 3/9"), std::string::npos)
      << screenshot_caption(info);
  EXPECT_NE(j["reproduce"]["notes"].dump().find("replay at step 3/9"), std::string::npos) << j["reproduce"]["notes"];
}

// Boxes the Predicted vs measured view drew (a region's entered nodes,
// colours by visits) are said on the caption and in the side-car, and noted
// as not replayed; a subtree's node note is not claimed for a region's boxes.
TEST(AppScreenshot, InsightBoxesAreSaidAndNotedAsNotReplayed) {
  ScreenshotInfo info = test_info();
  info.box_node_note = "node 1098: a leaf at depth 8, 3 primitives";
  info.boxes_of_region = true;
  info.boxes_by_visits = true;
  const std::string caption = screenshot_caption(info);
  EXPECT_NE(caption.find(", boxes: the nodes a heatmap region's rays entered, coloured by visits"), std::string::npos)
      << caption;
  EXPECT_EQ(caption.find("node 1098"), std::string::npos) << caption;
  const nlohmann::json j = screenshot_sidecar(info, "shot.png");
  EXPECT_EQ(j["boxes"]["region"], true);
  EXPECT_EQ(j["boxes"]["by_visits"], true);
  EXPECT_EQ(j["boxes"]["node_note"], "");
  const auto& notes = j["reproduce"]["notes"];
  ASSERT_EQ(notes.size(), 1u) << notes;
  EXPECT_NE(notes[0].get<std::string>().find("does not measure or select again"), std::string::npos) << notes;
}

TEST(AppScreenshot, AThinnedBoxOverlayIsSaidOnThePictureAndInTheSideCar) {
  ScreenshotInfo info = test_info();
  info.boxes_drawn = 200000;
  info.boxes_matched = 288291;
  EXPECT_EQ(screenshot_caption(info),
            info.scene + ", " + screenshot_caption(info.config) + ", boxes 200000 of 288291, ray of pixel 32,24");
  const nlohmann::json j = screenshot_sidecar(info, "shot.png");
  EXPECT_EQ(j["caption"], screenshot_caption(info));
  EXPECT_EQ(j["boxes"]["drawn"], 200000);
  EXPECT_EQ(j["boxes"]["matched"], 288291);
  const auto& notes = j["reproduce"]["notes"];
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0],
            "raster: the window drew 200000 of the 288291 boxes, spread evenly over the selection; the command line "
            "draws all");
  // All drawn: nothing added.
  info.boxes_drawn = info.boxes_matched = 5000;
  EXPECT_EQ(screenshot_caption(info), info.scene + ", " + screenshot_caption(info.config) + ", ray of pixel 32,24");
  EXPECT_TRUE(screenshot_sidecar(info, "shot.png")["reproduce"]["notes"].empty());
}

TEST(AppScreenshot, SideCarNotesWhatTheCommandLineCannotSay) {
  ScreenshotInfo info = test_info();
  ASSERT_EQ(apply_option(info.config, "structure", "kdtree"), "");
  ASSERT_EQ(apply_option(info.config, "kd-leaf", "6"), "");
  ASSERT_EQ(apply_option(info.config, "scale", "2,30"), "");
  info.camera_spec = "";
  const nlohmann::json j = screenshot_sidecar(info, "shot.png");
  const std::string cmd = j["reproduce"]["render_heatmap"];
  EXPECT_NE(cmd.find("--structure kdtree"), std::string::npos);
  EXPECT_NE(cmd.find("--max 30"), std::string::npos);
  EXPECT_EQ(cmd.find("--camera"), std::string::npos) << "the default view needs no --camera";
  std::string notes = j["reproduce"]["notes"].dump();
  EXPECT_NE(notes.find("kd-leaf=6"), std::string::npos) << notes;
  EXPECT_NE(notes.find("starts at 2"), std::string::npos) << notes;
}

TEST(AppScreenshot, DefaultFolderFollowsXdgPictures) {
  const char* old_pics = std::getenv("XDG_PICTURES_DIR");
  const std::string saved_pics = old_pics ? old_pics : "";
  const char* old_home = std::getenv("HOME");
  const std::string saved_home = old_home ? old_home : "";
  setenv("XDG_PICTURES_DIR", "/pics", 1);
  EXPECT_EQ(default_screenshot_dir(), fs::path("/pics/accelviz"));
  unsetenv("XDG_PICTURES_DIR");
  setenv("HOME", "/home/u", 1);
  EXPECT_EQ(default_screenshot_dir(), fs::path("/home/u/Pictures/accelviz"));
  if (old_pics) setenv("XDG_PICTURES_DIR", saved_pics.c_str(), 1);
  if (old_home) setenv("HOME", saved_home.c_str(), 1);
}

// The caption says which scene (a file by its name), the metric in the structure's words, and why a
// metric the structure does not count reads 0 (a lecture's teapot and teapot-in-a-stadium looked alike).
TEST(AppScreenshot, TheCaptionNamesTheSceneAndWhatTheMetricMeansHere) {
  ScreenshotInfo info = test_info();
  EXPECT_EQ(screenshot_caption(info).rfind("builtin:teapot?size=2000, bvh", 0), 0u) << screenshot_caption(info);
  info.scene = "/home/u/meshes/bunny.glb";
  EXPECT_EQ(screenshot_caption(info).rfind("bunny.glb, bvh", 0), 0u) << screenshot_caption(info);
  EXPECT_EQ(apply_option(info.config, "metric", "nodes"), "");
  EXPECT_EQ(apply_option(info.config, "structure", "grid"), "");
  EXPECT_NE(screenshot_caption(info).find("heatmap nodes (cells)"), std::string::npos) << screenshot_caption(info);
  EXPECT_EQ(apply_option(info.config, "structure", "bvh"), "");
  EXPECT_EQ(screenshot_caption(info).find("(cells)"), std::string::npos) << screenshot_caption(info);
  EXPECT_EQ(apply_option(info.config, "metric", "instances"), "");
  EXPECT_NE(screenshot_caption(info).find("(n/a: only a two-level structure (tlas) enters instances)"),
            std::string::npos)
      << screenshot_caption(info);
}
}  // namespace unity_test_app_screenshot
