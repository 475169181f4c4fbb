// load_scene: the one entry point the app uses; dispatches a command-line
// SCENE argument to the built-in generators or to a file loader.
#include "core/scene/load.h"

#include <cstdint>
#include <limits>
#include <string>

#include "core/util/file_checks.h"

namespace accelviz {

Scene load_scene(const std::string& spec) {
  if (spec.rfind("builtin:", 0) == 0) return make_builtin(spec);

  // Existence first: a mistyped path is the more common mistake, and
  // "unsupported file type" would hide it. The loaders check the rest.
  std::uintmax_t size = 0;
  if (const std::string problem = input_file_problem(spec, std::numeric_limits<std::uintmax_t>::max(), size);
      problem == "no such file" || problem.starts_with("cannot be read"))
    throw SceneError(spec + ": " + problem);

  const std::string ext = lower_extension(spec);
  if (ext == ".gltf" || ext == ".glb") return load_gltf(spec);
  if (ext == ".obj") return load_obj(spec);
  const std::string shown = ext.empty() ? std::string("(no extension)") : "'" + ext + "'";
  throw SceneError(spec + ": unsupported file type " + shown + " (expected .gltf, .glb or .obj)");
}

}  // namespace accelviz
