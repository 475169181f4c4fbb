// load_scene: the one entry point the app uses; dispatches a command-line
// SCENE argument to the built-in generators or to a file loader.
#include "core/scene/load.h"

#include <filesystem>
#include <string>

#include "core/util/file_checks.h"

namespace accelviz {

Scene load_scene(const std::string& spec) {
  if (spec.rfind("builtin:", 0) == 0) return make_builtin(spec);

  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(spec, ec);
  // Existence first: a mistyped path is the more common mistake, and
  // "unsupported file type" would hide it.
  if (ec || !fs::exists(st)) throw SceneError(spec + ": no such file");

  const std::string ext = lower_extension(spec);
  if (ext == ".gltf" || ext == ".glb") return load_gltf(spec);
  if (ext == ".obj") return load_obj(spec);
  const std::string shown = ext.empty() ? std::string("(no extension)") : "'" + ext + "'";
  throw SceneError(spec + ": unsupported file type " + shown + " (expected .gltf, .glb or .obj)");
}

}  // namespace accelviz
