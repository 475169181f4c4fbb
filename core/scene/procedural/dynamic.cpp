// builtin:dynamic — a scene that moves: thousands of small boxes flying
// over a lawn, each driven by glTF-style animation channels (translation on
// a loop of 5 keys, linear, step or cubic spline by box; rotation slerped
// between quaternions; every fifth box also pulses its scale on a cubic
// spline), and the lawn's blades waving (a MeshDeformer on the grass mesh).
// Rigid boxes touch only instance transforms and the TLAS per frame; the
// grass is one deforming BLAS, refitted or rebuilt (core/scene/animation.h).
#include <algorithm>
#include <cmath>
#include <string>

#include "core/scene/animation.h"
#include "core/scene/procedural/common.h"
#include "core/scene/procedural/generators.h"
#include "core/scene/procedural/random.h"
#include "core/scene/procedural/reproducible_fp.h"  // first: see there

namespace accelviz::procedural {

namespace {

constexpr int kKeys = 5;           // keys at t = 0, 1, 2, 3, 4 s; the last repeats the first (a loop)
constexpr float kBoxHalf = 0.04f;  // half edge of a box
constexpr float kGrassHeight = 0.3f;

glm::quat axis_angle(const glm::vec3& axis, double angle) {
  const SinCos h = sin_cos(0.5 * angle);
  const glm::vec3 a = axis * static_cast<float>(h.sin);
  return glm::quat(static_cast<float>(h.cos), a.x, a.y, a.z);
}

}  // namespace

Scene make_dynamic(const BuiltinArgs& args) {
  SplitMix64 rng(args.seed);
  const std::int64_t lawn_budget = std::max<std::int64_t>(5, args.size / 4);
  const std::int64_t boxes = std::max<std::int64_t>(1, (args.size - lawn_budget) / 12);

  // The lawn: builtin:grass's generator with a quarter of the budget.
  BuiltinArgs lawn_args = args;
  lawn_args.size = lawn_budget;
  Scene lawn = make_grass(lawn_args);
  Scene scene;
  std::uint32_t grass_mesh = 0;
  for (std::size_t i = 0; i < lawn.instances.size(); ++i) {
    const std::uint32_t m = add_mesh(scene, std::move(lawn.meshes[lawn.instances[i].mesh]));
    if (scene.meshes[m].name == "grass") grass_mesh = m;
    place_mesh(scene, m, scene.meshes[m].name);
  }
  const Aabb lawn_box = lawn.bounds();
  const float half = 0.5f * std::max(lawn_box.extent().x, lawn_box.extent().z);
  scene.deformers.push_back({grass_mesh, 0.06f, 0.5f, kGrassHeight});

  Mesh box;
  box.name = "box";
  append_box(box, glm::vec3(-kBoxHalf), glm::vec3(kBoxHalf));
  const std::uint32_t box_mesh = add_mesh(scene, std::move(box));

  Animation anim;
  anim.name = "flight";
  for (std::int64_t i = 0; i < boxes; ++i) {
    // A loop around a random centre above the lawn.
    const glm::vec2 c = rng.uniform2(-half, half);
    const float height = rng.uniform(0.2f, 1.0f);
    const float radius = rng.uniform(0.1f, 0.5f);
    const double phase = 2.0 * kPi * rng.uniform_double();
    const glm::vec3 axis = glm::normalize(rng.uniform3(-1.0f, 1.0f) + glm::vec3(0.0f, 0.0f, 1e-3f));
    const auto interp = static_cast<AnimationChannel::Interpolation>(i % 3);

    AnimationChannel tr;
    tr.path = AnimationChannel::Path::translation;
    tr.interpolation = interp;
    AnimationChannel rot;
    rot.path = AnimationChannel::Path::rotation;
    rot.interpolation = AnimationChannel::Interpolation::linear;
    glm::vec3 p0(0.0f);
    glm::quat q0(1.0f, 0.0f, 0.0f, 0.0f);
    for (int k = 0; k < kKeys; ++k) {
      tr.times.push_back(static_cast<float>(k));
      rot.times.push_back(static_cast<float>(k));
      const SinCos a = sin_cos(phase + 2.0 * kPi * (k % (kKeys - 1)) / (kKeys - 1));
      const glm::vec3 p(c.x + radius * static_cast<float>(a.cos), height, c.y + radius * static_cast<float>(a.sin));
      // Quarter turns about the box's axis; the last key is a full turn (slerp takes the short way).
      const glm::quat q = axis_angle(axis, 0.5 * kPi * k);
      if (k == 0) {
        p0 = p;
        q0 = q;
      }
      if (interp == AnimationChannel::Interpolation::cubic_spline) {
        // Tangents along the loop (per second): the circle's derivative.
        const glm::vec3 tangent(-radius * static_cast<float>(a.sin), 0.0f, radius * static_cast<float>(a.cos));
        const glm::vec3 tan = tangent * static_cast<float>(2.0 * kPi / (kKeys - 1));
        tr.values.emplace_back(tan, 0.0f);
        tr.values.emplace_back(p, 0.0f);
        tr.values.emplace_back(tan, 0.0f);
      } else {
        tr.values.emplace_back(p, 0.0f);
      }
      rot.values.emplace_back(q.x, q.y, q.z, q.w);
    }
    const float s0 = 1.0f;
    Node node;
    node.name = "box " + std::to_string(i);
    node.mesh = static_cast<int>(box_mesh);
    node.translation = p0;
    node.rotation = q0;
    node.scale = glm::vec3(s0);
    node.local = compose_trs(p0, q0, node.scale);  // as apply_animation does
    scene.nodes.push_back(node);
    const int node_id = static_cast<int>(scene.nodes.size()) - 1;
    Instance inst;
    inst.mesh = box_mesh;
    inst.node = static_cast<std::uint32_t>(node_id);
    inst.transform = node.local;
    scene.instances.push_back(inst);
    tr.node = rot.node = node_id;
    anim.channels.push_back(std::move(tr));
    anim.channels.push_back(std::move(rot));
    if (i % 5 == 0) {
      AnimationChannel sc;
      sc.node = node_id;
      sc.path = AnimationChannel::Path::scale;
      sc.interpolation = AnimationChannel::Interpolation::cubic_spline;
      for (int k = 0; k < kKeys; ++k) {
        sc.times.push_back(static_cast<float>(k));
        const float v = k % 2 == 0 ? 1.0f : 1.5f;
        sc.values.emplace_back(0.0f, 0.0f, 0.0f, 0.0f);  // in-tangent: flat
        sc.values.emplace_back(v, v, v, 0.0f);
        sc.values.emplace_back(0.0f, 0.0f, 0.0f, 0.0f);  // out-tangent
      }
      anim.channels.push_back(std::move(sc));
    }
  }
  scene.animations.push_back(std::move(anim));

  const Aabb view{glm::vec3(-half, 0.0f, -half), glm::vec3(half, 1.2f, half)};
  scene.cameras.push_back(frame_box("overview", view, glm::vec3(0.3f, 0.5f, 1.0f)));
  scene.lights.push_back(directional_light("sun", glm::vec3(-0.4f, -1.0f, -0.3f), 3.0f));
  finish(scene, args);
  return scene;
}

}  // namespace accelviz::procedural
