#pragma once
// Writes a Scene as glTF 2.0 (.gltf with an embedded base64 buffer, or .glb),
// so that built-in scenes can be saved as assets and reloaded with load_gltf.
#include "core/scene/scene.h"

#include <string>

namespace accelviz {

/// Writes meshes (float32 positions with accessor min/max, uint32 indices),
/// the node graph with each node's local transform (TRS, or a matrix where
/// the node had one or its TRS does not reproduce `local`), every instance as
/// a node referencing its mesh, cameras and KHR_lights_punctual lights (each
/// as an extra root node carrying its world placement).
///
/// Reloading the file gives the same world triangles in the same order when
/// the instances are in node depth-first order (as load_gltf produces them);
/// instances that no node represents become extra root nodes, appended.
/// Empty meshes are left out (glTF forbids empty accessors).
///
/// Refuses to replace an existing file unless `overwrite`; the file is written
/// beside the target and renamed into place, so a failure leaves no partial
/// file. Throws SceneError "<file>: <problem>".
void write_gltf(const Scene& scene, const std::string& path, bool binary, bool overwrite = false);

}  // namespace accelviz
