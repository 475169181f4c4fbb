// accelviz export SCENE OUT.(glb|gltf) [--force]: writes any scene accelviz
// can load (a built-in generator, a .gltf/.glb, an .obj) as glTF 2.0, so a
// procedural scene can be opened in other tools or shipped as a small asset.
#include <cstdio>
#include <memory>

#include "app/cli_common.h"
#include "core/scene/gltf_writer.h"
#include "core/util/file_checks.h"
#include "core/util/one_line.h"

namespace accelviz::cli {

namespace {

struct ExportOptions {
  std::string scene;
  std::string out;
  bool force = false;
};

int run_export(const ExportOptions& o, const GlobalOptions& global) {
  const std::string ext = lower_extension(o.out);
  const bool binary = ext == ".glb";
  if (const std::string bare = bare_extension(o.out); bare == ".glb" || bare == ".gltf")
    throw UsageError(o.out + ": a glTF file needs a name before " + bare);
  if (!binary && ext != ".gltf") throw UsageError(o.out + ": the output's name must end in .glb or .gltf");
  check_output_path(o.out, o.force);
  const Scene scene = load_scene_noting_warnings(o.scene, global.quiet);
  write_gltf(scene, o.out, binary, o.force);
  // The result goes to stdout whatever -q says (-q silences progress only).
  // glTF animations are not written (the nodes at rest): said, not dropped silently.
  const std::string left_out =
      scene.animations.empty()
          ? ""
          : "; not written: " + count_of(scene.animations.size(), "animation") + " (the nodes at rest)";
  std::printf("wrote %s: %s, %s, %s, %s, %s%s\n", path_line(absolute_path(o.out)).c_str(),
              count_of(scene.triangles.size(), "triangle").c_str(), count_of(scene.meshes.size(), "mesh").c_str(),
              count_of(scene.instances.size(), "instance").c_str(), count_of(scene.lights.size(), "light").c_str(),
              count_of(scene.cameras.size(), "camera").c_str(), left_out.c_str());
  return 0;
}

Command add_export_command(CLI::App& parent, const GlobalOptions& global) {
  auto o = std::make_shared<ExportOptions>();
  CLI::App* sub = parent.add_subcommand("export", "Write a scene (built-in, glTF or OBJ) as glTF 2.0 (.glb or .gltf)");
  sub->add_option("SCENE", o->scene, "Scene file (.gltf, .glb, .obj) or builtin:NAME[?key=value&...]")->required();
  sub->add_option("OUT", o->out, "Output file; .glb writes binary glTF, .gltf embeds the buffer as base64")
      ->required();
  sub->add_flag("--force,-f", o->force, "Replace OUT if it exists");
  return {sub, [o, &global] { return run_export(*o, global); }};
}

const CommandRegistration register_export{add_export_command};

}  // namespace

}  // namespace accelviz::cli
