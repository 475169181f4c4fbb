#pragma once
// Scene loading entry points. Every failure throws SceneError with a single
// line "<file>: <problem>"; nothing here crashes, hangs or allocates without
// bound on bad input.
#include "core/scene/scene.h"

#include <string>
#include <vector>

namespace accelviz {

/// Loads SCENE as the command line names it: a path to .gltf/.glb/.obj, or a
/// built-in spec "builtin:NAME[?key=value&...]" (e.g.
/// "builtin:teapot-stadium?size=1000000&seed=1").
Scene load_scene(const std::string& spec);

/// glTF 2.0 (.gltf or .glb) through tinygltf, validated by us.
Scene load_gltf(const std::string& path);

/// Wavefront OBJ through tinyobjloader.
Scene load_obj(const std::string& path);

/// A built-in procedural scene from its spec (with or without "builtin:").
Scene make_builtin(const std::string& spec);

struct BuiltinSceneInfo {
  std::string name;         ///< as used in "builtin:NAME"
  std::string description;  ///< one line
  std::string parameters;   ///< e.g. "size (triangles, default 100000), seed"
};
/// Every built-in scene, in the order `--help` lists them.
const std::vector<BuiltinSceneInfo>& builtin_scenes();

/// The scene the app and Quick start open when given no file.
inline constexpr const char* kDemoScene = "builtin:teapot-stadium";

}  // namespace accelviz
