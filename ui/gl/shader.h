#pragma once
// GLSL programs built from the files in shaders/. Every file is embedded in
// the binary at build time (ui/embed_shaders.cmake); setting
// ACCELVIZ_SHADER_DIR to a folder makes files found there win over the
// embedded copies, so shaders can be edited while the program runs
// (Renderer::reload_shaders).
#include "ui/gl/gl.h"

#include <glm/glm.hpp>

#include <initializer_list>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace accelviz {

/// One embedded file: its name in shaders/ ("mesh.vert") and its text.
struct EmbeddedShader {
  const char* name;
  const char* source;
};
/// All embedded files, sorted by name (defined in the generated embedded_shaders.cpp).
std::span<const EmbeddedShader> embedded_shaders();

/// The text of one shader and where it came from.
struct ShaderSource {
  std::string name;  ///< "mesh.vert"
  std::string path;  ///< the file read, or "shaders/mesh.vert" for the embedded copy: what errors name
  std::string text;
};

/// `name` from the override folder (shader_dir()) when there is one and the
/// file exists there, otherwise the embedded copy. Throws ShaderError when
/// neither has it.
ShaderSource load_shader_source(std::string_view name);

/// The folder whose files win over the embedded shaders: the one set by
/// set_shader_dir(), else $ACCELVIZ_SHADER_DIR; "" for none.
std::string shader_dir();
/// Sets the override folder for this process (replacing $ACCELVIZ_SHADER_DIR);
/// it applies to programs built from then on (Renderer::reload_shaders).
void set_shader_dir(std::string dir);

/// A compile or link failure. what() is one line,
/// "<file>:<line>:<column>: error: <driver message>" for compile errors
/// (line 0 when the driver gave none), "<file> + <file>: link error: ..."
/// for link errors; log() keeps the driver's full info log.
class ShaderError : public std::runtime_error {
 public:
  ShaderError(const std::string& message, std::string file = {}, int line = 0, std::string log = {})
      : std::runtime_error(message), file_(std::move(file)), line_(line), log_(std::move(log)) {}
  const std::string& file() const { return file_; }
  int line() const { return line_; }
  const std::string& log() const { return log_; }

 private:
  std::string file_;
  int line_;
  std::string log_;
};

/// One message of a driver info log.
struct ShaderDiagnostic {
  int line = 0;         ///< 1-based line in the shader file; 0 when unknown
  int column = 0;       ///< 1-based column; 0 when unknown
  std::string message;  ///< "error: syntax error, unexpected ..." as the driver wrote it
};
/// Parses an info log: Mesa writes "0:LINE(COL): error: ...", NVIDIA
/// "0(LINE) : error C0000: ...". Lines in neither form are kept with line 0.
/// The source-string index (the leading 0) is ours to map: we compile each
/// file as one string with nothing prepended, so driver lines are file lines.
std::vector<ShaderDiagnostic> parse_shader_log(std::string_view log);

class ShaderProgram {
 public:
  ShaderProgram() = default;
  ~ShaderProgram();
  ShaderProgram(ShaderProgram&& o) noexcept;
  ShaderProgram& operator=(ShaderProgram&& o) noexcept;
  ShaderProgram(const ShaderProgram&) = delete;
  ShaderProgram& operator=(const ShaderProgram&) = delete;

  /// Compiles the named files (stage from the extension: .vert, .frag,
  /// .comp) and links them; throws ShaderError naming the file and line.
  static ShaderProgram build(std::initializer_list<std::string_view> names);

  GLuint id() const { return id_; }
  void use() const { glUseProgram(id_); }

  /// Uniform setters by name; a name the program does not use (optimised
  /// away, or removed in a live edit) is ignored, as GL does for location -1.
  void set(const char* name, int v) const;
  void set(const char* name, float v) const;
  void set(const char* name, const glm::vec2& v) const;
  void set(const char* name, const glm::vec3& v) const;
  void set(const char* name, const glm::vec4& v) const;
  void set(const char* name, const glm::mat4& v) const;

 private:
  explicit ShaderProgram(GLuint id) : id_(id) {}
  GLuint id_ = 0;
};

}  // namespace accelviz
