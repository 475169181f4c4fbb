// Shader compile and link errors name the file and the line; the override
// directory (ACCELVIZ_SHADER_DIR) replaces embedded shaders, also live.
#include <sys/stat.h>

#include <filesystem>
#include <fstream>

#include "gl_fixture.h"
#include "ui/gl/shader.h"

namespace accelviz::test {
namespace {

// Points ACCELVIZ_SHADER_DIR at a directory for one scope.
class ShaderDirOverride {
 public:
  explicit ShaderDirOverride(const std::filesystem::path& dir) { setenv("ACCELVIZ_SHADER_DIR", dir.c_str(), 1); }
  ~ShaderDirOverride() { unsetenv("ACCELVIZ_SHADER_DIR"); }
};

void write_file(const std::filesystem::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}

// The embedded mesh.frag with line `line` (1-based) replaced by `text`.
std::string mesh_frag_with_line(int line, const std::string& text) {
  const std::string source = load_shader_source("mesh.frag").text;
  std::string out;
  int n = 1;
  std::size_t start = 0;
  while (start < source.size()) {
    const std::size_t end = source.find('\n', start);
    const std::string current = source.substr(start, end == std::string::npos ? std::string::npos : end - start);
    out += (n == line ? text : current) + "\n";
    ++n;
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return out;
}

class ShaderErrors : public ::testing::Test {
 protected:
  void SetUp() override { context_ = std::make_unique<OsMesaContext>(kWidth, kHeight); }
  std::unique_ptr<OsMesaContext> context_;
  TempDir dir_{"shaders"};
};

TEST_F(ShaderErrors, SyntaxErrorNamesTheFileAndTheLine) {
  constexpr int kBrokenLine = 21;
  write_file(dir_.path() / "mesh.frag", mesh_frag_with_line(kBrokenLine, "  float broken = ;"));
  ShaderDirOverride env(dir_.path());
  try {
    Renderer renderer;
    FAIL() << "the broken shader compiled";
  } catch (const ShaderError& e) {
    const std::string file = (dir_.path() / "mesh.frag").string();
    EXPECT_EQ(e.file(), file);
    EXPECT_EQ(e.line(), kBrokenLine);
    // "<file>:<line>:<column>: error: ..." - one line, like a compiler's.
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(file + ":" + std::to_string(kBrokenLine) + ":", 0), 0u) << what;
    EXPECT_NE(what.find("error"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_FALSE(e.log().empty());
  }
}

TEST_F(ShaderErrors, LinkErrorNamesBothFiles) {
  // A fragment input the vertex shader does not write fails at link time.
  write_file(dir_.path() / "color.frag",
             "#version 450 core\nin vec4 v_colour;\nout vec4 frag_color;\nvoid main() { frag_color = v_colour; }\n");
  ShaderDirOverride env(dir_.path());
  try {
    (void)ShaderProgram::build({"box.vert", "color.frag"});
    FAIL() << "the mismatched program linked";
  } catch (const ShaderError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("shaders/box.vert + " + (dir_.path() / "color.frag").string() + ": link error:"),
              std::string::npos)
        << what;
  }
}

TEST_F(ShaderErrors, UnknownShaderIsReported) {
  try {
    (void)ShaderProgram::build({"nonexistent.vert"});
    FAIL() << "no error";
  } catch (const ShaderError& e) {
    EXPECT_NE(std::string(e.what()).find("shaders/nonexistent.vert: no such shader"), std::string::npos) << e.what();
  }
}

TEST_F(ShaderErrors, OverrideDirectoryWinsOnlyForFilesItHas) {
  write_file(dir_.path() / "color.frag",
             "#version 450 core\nout vec4 frag_color;\nvoid main() { frag_color = vec4(1); }\n");
  ShaderDirOverride env(dir_.path());
  EXPECT_EQ(load_shader_source("color.frag").path, (dir_.path() / "color.frag").string());
  EXPECT_EQ(load_shader_source("mesh.vert").path, "shaders/mesh.vert");
}

// A shader file in the override folder that is a FIFO blocked the reload
// (the window stopped); one that is a folder read as an empty shader.
TEST_F(ShaderErrors, AFifoOrFolderInTheOverrideFolderIsNamedNotRead) {
  ASSERT_EQ(::mkfifo((dir_.path() / "mesh.frag").c_str(), 0644), 0);
  std::filesystem::create_directories(dir_.path() / "color.frag");
  ShaderDirOverride env(dir_.path());
  for (const auto& [name, problem] :
       {std::pair{"mesh.frag", "is not a regular file"}, std::pair{"color.frag", "is a directory, not a file"}}) {
    try {
      (void)load_shader_source(name);
      ADD_FAILURE() << name << " was read";
    } catch (const ShaderError& e) {
      EXPECT_EQ(std::string(e.what()), (dir_.path() / name).string() + ": " + problem);
    }
  }
}

TEST_F(ShaderErrors, LiveReloadKeepsOldProgramsOnErrorAndPicksUpFixes) {
  Renderer renderer;  // embedded shaders
  std::vector<Triangle> wall;
  add_quad_xy(wall, -5.0f, -5.0f, 5.0f, 5.0f, 0.0f);
  renderer.set_triangles(wall);
  RenderView view;
  renderer.render(view, 32, 32);
  const glm::u8vec4 before = renderer.read_pixels().at(16, 16);

  ShaderDirOverride env(dir_.path());
  write_file(dir_.path() / "mesh.frag", mesh_frag_with_line(3, "this is not glsl"));
  EXPECT_THROW(renderer.reload_shaders(), ShaderError);
  renderer.render(view, 32, 32);  // still the old programs
  EXPECT_EQ(renderer.read_pixels().at(16, 16), before);

  // A working edit: paint everything magenta.
  write_file(dir_.path() / "mesh.frag",
             "#version 450 core\nout vec4 frag_color;\nvoid main() { frag_color = vec4(1.0, 0.0, 1.0, 1.0); }\n");
  renderer.reload_shaders();
  renderer.render(view, 32, 32);
  EXPECT_EQ(renderer.read_pixels().at(16, 16), glm::u8vec4(255, 0, 255, 255));
}

}  // namespace
}  // namespace accelviz::test
