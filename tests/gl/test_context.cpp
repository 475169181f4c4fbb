// The OSMesa side of the context seam: a real 4.5 core context, GL loaded
// through OSMesaGetProcAddress, errors reported per pass, and no libGL in
// the process.
#include "gl_fixture.h"

#include "ui/gl/egl_context.h"
#include "ui/gl/gl.h"
#include "ui/gl/headless.h"
#include "ui/gl/shader.h"

#include <cstdio>
#include <fstream>
#include <sstream>

namespace accelviz::test {
namespace {

TEST(OsMesaContext, GivesAnOpenGl45CoreContext) {
  OsMesaContext ctx(64, 48);
  const GlInfo& info = ctx.info();
  EXPECT_GE(info.major * 10 + info.minor, 45) << info.version;
  EXPECT_TRUE(info.core_profile) << info.version;
  // The same, asked again through the loaded entry points.
  const GlInfo again = query_gl_info();
  EXPECT_EQ(again.version, info.version);
  EXPECT_FALSE(info.renderer.empty());
  EXPECT_EQ(ctx.width(), 64);
  EXPECT_EQ(ctx.height(), 48);
  EXPECT_EQ(ctx.kind(), "osmesa");
}

TEST(OsMesaContext, ComputeShadersAreAvailable) {
  // Core 4.5 includes compute; the loader must have found the entry point.
  OsMesaContext ctx(16, 16);
  EXPECT_NE(glad_glDispatchCompute, nullptr);
  GLint max_invocations = 0;
  glGetIntegerv(GL_MAX_COMPUTE_WORK_GROUP_INVOCATIONS, &max_invocations);
  EXPECT_GE(max_invocations, 1024);  // the minimum 4.3+ guarantees
}

TEST(OsMesaContext, RejectsAnEmptyImageSize) {
  EXPECT_THROW(OsMesaContext(0, 10), GlError);
}

/// Pixel (3, 3) of an 8×8 picture of `background` drawn by a renderer made,
/// used and destroyed in the current context.
glm::u8vec4 drawn_background(const glm::vec3& background) {
  Renderer r;
  RenderView view;
  view.background = background;
  r.render(view, 8, 8);
  return r.read_pixels().at(3, 3);
}

TEST(OsMesaContext, TwoContextsTakeTurns) {
  // GL objects belong to their context: each renderer is used and destroyed
  // with its own context current.
  OsMesaContext a(32, 32);
  OsMesaContext b(16, 16);
  a.make_current();
  auto ra = std::make_unique<Renderer>();
  RenderView view;
  view.background = {1.0f, 0.0f, 0.0f};
  ra->render(view, 8, 8);
  b.make_current();
  EXPECT_EQ(drawn_background({0.0f, 0.0f, 1.0f}), glm::u8vec4(0, 0, 255, 255));
  a.make_current();
  EXPECT_EQ(ra->read_pixels().at(3, 3), glm::u8vec4(255, 0, 0, 255));
  ra.reset();
  check_gl_errors("renderer teardown");
}

// The EGL side: a 4.5 core context on a device without any surface (a GPU
// where there is one; in CI, Mesa's software device), GL loaded through
// eglGetProcAddress.
TEST(EglContext, GivesAnOpenGl45CoreContextOnADevice) {
  EglContext ctx(64, 48, EglContext::Devices::any);
  const GlInfo& info = ctx.info();
  EXPECT_GE(info.major * 10 + info.minor, 45) << info.version;
  EXPECT_TRUE(info.core_profile) << info.version;
  EXPECT_EQ(query_gl_info().renderer, info.renderer);
  EXPECT_EQ(ctx.kind(), "egl");
  EXPECT_EQ(ctx.width(), 64);
  EXPECT_EQ(ctx.height(), 48);
  // Mesa's software device renders with llvmpipe; a GPU's driver names the GPU.
  EXPECT_EQ(ctx.software(), info.renderer.find("llvmpipe") != std::string::npos) << info.renderer;
  EXPECT_NE(glad_glDispatchCompute, nullptr);
  EXPECT_THROW(EglContext(0, 5), GlError);
}

TEST(EglContext, TakesTurnsWithOsMesaAndDrawsInItsFramebuffer) {
  // The glad table is refilled on every switch between the two libraries'
  // entry points: each renderer draws and reads back in its own context.
  EglContext e(16, 16);
  auto re = std::make_unique<Renderer>();
  RenderView view;
  view.background = {0.0f, 1.0f, 0.0f};
  re->render(view, 8, 8);
  {
    OsMesaContext o(16, 16);
    EXPECT_EQ(drawn_background({0.0f, 0.0f, 1.0f}), glm::u8vec4(0, 0, 255, 255));
  }
  e.make_current();
  EXPECT_EQ(re->read_pixels().at(3, 3), glm::u8vec4(0, 255, 0, 255));
  EglContext second(8, 8);  // a second context on the same device shares its display
  second.make_current();
  EXPECT_EQ(drawn_background({1.0f, 0.0f, 0.0f}), glm::u8vec4(255, 0, 0, 255));
  e.make_current();  // still usable after the second one's renderer is gone
  EXPECT_EQ(re->read_pixels().at(3, 3), glm::u8vec4(0, 255, 0, 255));
  re.reset();
  check_gl_errors("egl renderer teardown");
}

TEST(EglContext, HardwareOnlyTakesAGpuOrSaysThereIsNone) {
  try {
    EglContext ctx(16, 16, EglContext::Devices::hardware_only);
    EXPECT_FALSE(ctx.software()) << ctx.info().renderer;
    EXPECT_EQ(ctx.info().renderer.find("llvmpipe"), std::string::npos) << ctx.info().renderer;
  } catch (const GlError& e) {
    // No GPU here (CI): one line that says so.
    const std::string what = e.what();
    EXPECT_NE(what.find("EGL"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(HeadlessContext, PicksTheContextByName) {
  EXPECT_EQ(make_headless_context(8, 8, "osmesa")->kind(), "osmesa");
  EXPECT_EQ(make_headless_context(8, 8, "egl")->kind(), "egl");
  // auto: EGL only on a GPU, else OSMesa (llvmpipe either way in CI).
  const auto a = make_headless_context(8, 8, "auto");
  if (a->kind() == "egl")
    EXPECT_FALSE(dynamic_cast<const EglContext&>(*a).software());
  else
    EXPECT_EQ(a->kind(), "osmesa");
  EXPECT_GE(a->info().major * 10 + a->info().minor, 45);
  EXPECT_THROW(make_headless_context(8, 8, "glx"), std::invalid_argument);
}

TEST(GlErrors, CheckNamesTheErrorAndThePass) {
  OsMesaContext ctx(16, 16);
  check_gl_errors("clean state");  // nothing pending
  glEnable(0xFFFF);                // not a capability: GL_INVALID_ENUM
  try {
    check_gl_errors("box pass");
    FAIL() << "no GlError";
  } catch (const GlError& e) {
    EXPECT_STREQ(e.what(), "GL_INVALID_ENUM after box pass");
  }
  check_gl_errors("after draining");  // the flag was consumed
}

// The rule of the seam: GL comes from GetProcAddress, so the test binary
// (which uses OSMesa and links GLFW too) must not need libGL.so at all.
TEST(Linking, TestBinaryDoesNotLinkLibGL) {
  // /proc/self/exe read here, in this process (inside popen it would be the shell).
  const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  FILE* pipe = popen(("ldd '" + self + "' 2>&1").c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string out;
  char buf[512];
  while (fgets(buf, sizeof buf, pipe)) out += buf;
  ASSERT_EQ(pclose(pipe), 0) << out;
  EXPECT_NE(out.find("libOSMesa"), std::string::npos) << out;
  EXPECT_EQ(out.find("libGL.so"), std::string::npos) << out;
  EXPECT_EQ(out.find("libGLX"), std::string::npos) << out;
  EXPECT_EQ(out.find("libOpenGL"), std::string::npos) << out;
}

TEST(Linking, NoLibGLIsLoadedForHeadlessRendering) {
  OsMesaContext ctx(32, 32);
  Renderer r;
  r.render(RenderView{}, 32, 32);
  std::ifstream maps("/proc/self/maps");
  std::stringstream text;
  text << maps.rdbuf();
  EXPECT_EQ(text.str().find("libGL.so"), std::string::npos);
  EXPECT_EQ(text.str().find("libGLX"), std::string::npos);
}

TEST(ShaderLog, ParsesMesaLines) {
  const auto d =
      parse_shader_log("0:12(5): error: syntax error, unexpected IDENTIFIER\n0:3(1): warning: unused variable\n");
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d[0].line, 12);
  EXPECT_EQ(d[0].column, 5);
  EXPECT_EQ(d[0].message, "error: syntax error, unexpected IDENTIFIER");
  EXPECT_EQ(d[1].line, 3);
}

TEST(ShaderLog, ParsesNvidiaLines) {
  const auto d = parse_shader_log("0(27) : error C1008: undefined variable \"foo\"");
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].line, 27);
  EXPECT_EQ(d[0].column, 0);
  EXPECT_EQ(d[0].message, "error C1008: undefined variable \"foo\"");
}

TEST(ShaderLog, KeepsUnrecognisedLinesWithoutALine) {
  const auto d = parse_shader_log("error: linking with uncompiled shader\n\n");
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].line, 0);
  EXPECT_EQ(d[0].message, "error: linking with uncompiled shader");
}

TEST(EmbeddedShaders, EveryShaderFileIsEmbedded) {
  // The build embeds shaders/*.{vert,frag,comp}; each compiles as found in the tree.
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(ACCELVIZ_SOURCE_DIR "/shaders")) {
    const std::string ext = e.path().extension().string();
    if (ext == ".vert" || ext == ".frag" || ext == ".comp") names.push_back(e.path().filename().string());
  }
  ASSERT_FALSE(names.empty());
  for (const std::string& n : names) {
    const ShaderSource s = load_shader_source(n);
    std::ifstream in(std::string(ACCELVIZ_SOURCE_DIR "/shaders/") + n, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    EXPECT_EQ(s.text, text.str()) << n;
    EXPECT_EQ(s.path, "shaders/" + n);
  }
}

}  // namespace
}  // namespace accelviz::test
