#include "ui/gl/shader.h"

#include <charconv>
#include <cstdlib>
#include <filesystem>
#include <glm/gtc/type_ptr.hpp>
#include <optional>
#include <utility>

#include "core/util/file_checks.h"

namespace accelviz {

namespace {
std::optional<std::string>& shader_dir_override() {
  static std::optional<std::string> dir;  // GL thread only, as every shader build
  return dir;
}
}  // namespace

std::string shader_dir() {
  if (shader_dir_override()) return *shader_dir_override();
  const char* dir = std::getenv("ACCELVIZ_SHADER_DIR");
  return dir ? dir : "";
}

void set_shader_dir(std::string dir) {
  shader_dir_override() = std::move(dir);
}

ShaderSource load_shader_source(std::string_view name) {
  if (const std::string dir = shader_dir(); !dir.empty()) {
    const std::filesystem::path path = std::filesystem::path(dir) / std::string(name);
    // A file the folder does not have comes from the embedded copies; one it
    // has must be a regular file (a FIFO blocked the reload, a folder read
    // as an empty shader).
    std::string text;
    const std::string problem = read_text_file(path.string(), std::uintmax_t{1} << 20, text);
    if (problem.empty()) return {std::string(name), path.string(), std::move(text)};
    if (problem != "no such file") throw ShaderError(path.string() + ": " + problem, path.string());
  }
  for (const EmbeddedShader& s : embedded_shaders()) {
    if (name == s.name) return {std::string(name), "shaders/" + std::string(name), s.source};
  }
  throw ShaderError("shaders/" + std::string(name) + ": no such shader (neither embedded nor in the shader folder)",
                    "shaders/" + std::string(name));
}

namespace {

// Reads a decimal number at s[pos...]; advances pos. False when none.
bool read_int(std::string_view s, std::size_t& pos, int& out) {
  const char* first = s.data() + pos;
  const auto [end, ec] = std::from_chars(first, s.data() + s.size(), out);
  if (ec != std::errc() || end == first) return false;
  pos += static_cast<std::size_t>(end - first);
  return true;
}

bool starts_at(std::string_view s, std::size_t pos, std::string_view prefix) {
  return s.substr(pos, prefix.size()) == prefix;
}

std::string_view trim_left(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  return s;
}

ShaderDiagnostic parse_log_line(std::string_view line) {
  ShaderDiagnostic d;
  std::size_t pos = 0;
  int string_index = 0, line_no = 0, column = 0;
  if (read_int(line, pos, string_index)) {
    const std::size_t after_index = pos;
    // Mesa: "0:12(5): error: ..."
    if (starts_at(line, pos, ":") && read_int(line, ++pos, line_no) && starts_at(line, pos, "(") &&
        read_int(line, ++pos, column) && starts_at(line, pos, "):")) {
      d.line = line_no;
      d.column = column;
      d.message = std::string(trim_left(line.substr(pos + 2)));
      return d;
    }
    // NVIDIA: "0(12) : error C0000: ..."
    pos = after_index;
    if (starts_at(line, pos, "(") && read_int(line, ++pos, line_no) && starts_at(line, pos, ")")) {
      std::string_view rest = trim_left(line.substr(pos + 1));
      if (!rest.empty() && rest.front() == ':') rest.remove_prefix(1);
      d.line = line_no;
      d.message = std::string(trim_left(rest));
      return d;
    }
  }
  d.message = std::string(trim_left(line));
  return d;
}

GLenum stage_of(std::string_view name) {
  auto ends_with = [&](std::string_view ext) { return name.ends_with(ext); };
  if (ends_with(".vert")) return GL_VERTEX_SHADER;
  if (ends_with(".frag")) return GL_FRAGMENT_SHADER;
  if (ends_with(".comp")) return GL_COMPUTE_SHADER;
  if (ends_with(".geom")) return GL_GEOMETRY_SHADER;
  throw ShaderError("shaders/" + std::string(name) + ": unknown shader stage (expected .vert, .frag or .comp)",
                    std::string(name));
}

std::string info_log(GLuint object, bool is_program) {
  GLint length = 0;
  if (is_program) {
    glGetProgramiv(object, GL_INFO_LOG_LENGTH, &length);
  } else {
    glGetShaderiv(object, GL_INFO_LOG_LENGTH, &length);
  }
  std::string log(static_cast<std::size_t>(length > 0 ? length : 0), '\0');
  if (length > 0) {
    if (is_program) {
      glGetProgramInfoLog(object, length, nullptr, log.data());
    } else {
      glGetShaderInfoLog(object, length, nullptr, log.data());
    }
  }
  while (!log.empty() && (log.back() == '\0' || log.back() == '\n')) log.pop_back();
  return log;
}

// First diagnostic that is an error (drivers list warnings too), else the first line.
ShaderDiagnostic first_error(std::string_view log) {
  const std::vector<ShaderDiagnostic> all = parse_shader_log(log);
  for (const ShaderDiagnostic& d : all) {
    if (d.message.find("error") != std::string::npos) return d;
  }
  return all.empty() ? ShaderDiagnostic{0, 0, "compilation failed (empty info log)"} : all.front();
}

GLuint compile(const ShaderSource& src) {
  const GLuint shader = glCreateShader(stage_of(src.name));
  const char* text = src.text.c_str();
  const GLint length = static_cast<GLint>(src.text.size());
  // One string, nothing prepended: the driver's line numbers are the file's.
  glShaderSource(shader, 1, &text, &length);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    const std::string log = info_log(shader, false);
    glDeleteShader(shader);
    const ShaderDiagnostic d = first_error(log);
    std::string where = src.path + ":" + std::to_string(d.line);
    if (d.column > 0) where += ":" + std::to_string(d.column);
    throw ShaderError(where + ": " + d.message, src.path, d.line, log);
  }
  return shader;
}

}  // namespace

std::vector<ShaderDiagnostic> parse_shader_log(std::string_view log) {
  std::vector<ShaderDiagnostic> out;
  while (!log.empty()) {
    const std::size_t nl = log.find('\n');
    std::string_view line = log.substr(0, nl);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (!trim_left(line).empty()) out.push_back(parse_log_line(line));
    if (nl == std::string_view::npos) break;
    log.remove_prefix(nl + 1);
  }
  return out;
}

ShaderProgram ShaderProgram::build(std::initializer_list<std::string_view> names) {
  std::vector<ShaderSource> sources;
  for (std::string_view n : names) sources.push_back(load_shader_source(n));

  std::vector<GLuint> shaders;
  auto delete_shaders = [&] {
    for (GLuint s : shaders) glDeleteShader(s);
  };
  try {
    for (const ShaderSource& s : sources) shaders.push_back(compile(s));
  } catch (...) {
    delete_shaders();
    throw;
  }

  const GLuint program = glCreateProgram();
  for (GLuint s : shaders) glAttachShader(program, s);
  glLinkProgram(program);
  for (GLuint s : shaders) glDetachShader(program, s);
  delete_shaders();

  GLint ok = GL_FALSE;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    const std::string log = info_log(program, true);
    glDeleteProgram(program);
    std::string files;
    for (const ShaderSource& s : sources) files += (files.empty() ? "" : " + ") + s.path;
    const ShaderDiagnostic d = first_error(log);
    throw ShaderError(files + ": link error: " + d.message, sources.front().path, 0, log);
  }
  return ShaderProgram(program);
}

ShaderProgram::~ShaderProgram() {
  if (id_) glDeleteProgram(id_);
}

ShaderProgram::ShaderProgram(ShaderProgram&& o) noexcept : id_(std::exchange(o.id_, 0)) {}

ShaderProgram& ShaderProgram::operator=(ShaderProgram&& o) noexcept {
  if (this != &o) {
    if (id_) glDeleteProgram(id_);
    id_ = std::exchange(o.id_, 0);
  }
  return *this;
}

void ShaderProgram::set(const char* name, int v) const {
  glProgramUniform1i(id_, glGetUniformLocation(id_, name), v);
}
void ShaderProgram::set(const char* name, float v) const {
  glProgramUniform1f(id_, glGetUniformLocation(id_, name), v);
}
void ShaderProgram::set(const char* name, const glm::vec2& v) const {
  glProgramUniform2fv(id_, glGetUniformLocation(id_, name), 1, glm::value_ptr(v));
}
void ShaderProgram::set(const char* name, const glm::vec3& v) const {
  glProgramUniform3fv(id_, glGetUniformLocation(id_, name), 1, glm::value_ptr(v));
}
void ShaderProgram::set(const char* name, const glm::vec4& v) const {
  glProgramUniform4fv(id_, glGetUniformLocation(id_, name), 1, glm::value_ptr(v));
}
void ShaderProgram::set(const char* name, const glm::mat4& v) const {
  glProgramUniformMatrix4fv(id_, glGetUniformLocation(id_, name), 1, GL_FALSE, glm::value_ptr(v));
}

}  // namespace accelviz
