// glTF morph targets: POSITION deltas and default weights are loaded, a
// weights channel is sampled (linear, step, cubic spline) and shapes the
// mesh, and the animator refits (or rebuilds) that mesh's BLAS so that
// queries equal a fresh build over the morphed vertices.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/accel/bvh/bvh.h"
#include "core/accel/tlas/tlas.h"
#include "core/query/camera.h"
#include "core/scene/animation.h"
#include "core/scene/effects.h"
#include "core/scene/load.h"
#include "tests/core/base64.h"
#include "tests/support/temp_dir.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_morph_targets {

using namespace accelviz;
using nlohmann::json;
namespace fs = std::filesystem;
using P = AnimationChannel::Path;
using I = AnimationChannel::Interpolation;

/// A glTF document in memory: one embedded buffer, float and u32 accessors.
struct MorphGltf {
  json doc = {{"asset", {{"version", "2.0"}}}};
  std::vector<unsigned char> bin;

  int accessor(const void* data, std::size_t bytes, int component, std::size_t count, const char* type) {
    const std::size_t offset = bin.size();
    bin.resize(offset + bytes);
    std::memcpy(bin.data() + offset, data, bytes);
    doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}});
    doc["accessors"].push_back({{"bufferView", doc["bufferViews"].size() - 1},
                                {"componentType", component},
                                {"count", count},
                                {"type", type}});
    return int(doc["accessors"].size() - 1);
  }
  int vec3s(const std::vector<glm::vec3>& v) { return accessor(v.data(), v.size() * 12, 5126, v.size(), "VEC3"); }
  int scalars(const std::vector<float>& f) { return accessor(f.data(), f.size() * 4, 5126, f.size(), "SCALAR"); }
  int indices(const std::vector<std::uint32_t>& i) {
    return accessor(i.data(), i.size() * 4, 5125, i.size(), "SCALAR");
  }

  std::string write(const fs::path& path) const {
    json d = doc;
    d["buffers"] = json::array(
        {json{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + test::base64(bin)}}});
    std::ofstream(path) << d.dump(1);
    return path.string();
  }
};

const std::vector<glm::vec3> kQuad = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
const std::vector<glm::vec3> kLift = {{0, 0, 0}, {0, 0, 0}, {0, 0, 1}, {0, 0, 1}};     // target 0: top edge up in z
const std::vector<glm::vec3> kWiden = {{-1, 0, 0}, {1, 0, 0}, {1, 0, 0}, {-1, 0, 0}};  // target 1: wider in x

/// A quad mesh with two morph targets, default weights (0.25, 0), two nodes
/// instancing it, and a linear weights channel on node 0: keys at 0, 1, 2 s
/// with weights (0, 0), (1, 0.5), (0.5, 1).
MorphGltf morph_quad_file() {
  MorphGltf g;
  const int pos = g.vec3s(kQuad);
  const int idx = g.indices({0, 1, 2, 0, 2, 3});
  const int t0 = g.vec3s(kLift);
  const int t1 = g.vec3s(kWiden);
  g.doc["meshes"] = json::array({json{
      {"primitives", json::array({json{{"attributes", {{"POSITION", pos}}},
                                       {"indices", idx},
                                       {"targets", json::array({json{{"POSITION", t0}}, json{{"POSITION", t1}}})}}})},
      {"weights", {0.25, 0.0}}}});
  g.doc["nodes"] = json::array({json{{"mesh", 0}}, json{{"mesh", 0}, {"translation", {3.0, 0.0, 0.0}}}});
  g.doc["scenes"] = json::array({json{{"nodes", {0, 1}}}});
  g.doc["scene"] = 0;
  const int times = g.scalars({0.0f, 1.0f, 2.0f});
  const int weights = g.scalars({0.0f, 0.0f, 1.0f, 0.5f, 0.5f, 1.0f});
  g.doc["animations"] = json::array(
      {json{{"samplers", json::array({json{{"input", times}, {"output", weights}}})},
            {"channels", json::array({json{{"sampler", 0}, {"target", {{"node", 0}, {"path", "weights"}}}}})}}});
  return g;
}

void expect_positions(const std::vector<glm::vec3>& got, const std::vector<float>& w) {
  ASSERT_EQ(got.size(), kQuad.size());
  for (std::size_t i = 0; i < kQuad.size(); ++i) {
    const glm::vec3 want = kQuad[i] + w[0] * kLift[i] + w[1] * kWiden[i];
    EXPECT_FLOAT_EQ(got[i].x, want.x) << "vertex " << i;
    EXPECT_FLOAT_EQ(got[i].y, want.y) << "vertex " << i;
    EXPECT_FLOAT_EQ(got[i].z, want.z) << "vertex " << i;
  }
}

TEST(MorphTargets, LoadedSampledAndAppliedToTheMesh) {
  const test_support::TempDir dir("morph");
  const Scene s = load_gltf(morph_quad_file().write(dir.path() / "morph.gltf"));
  ASSERT_EQ(s.meshes.size(), 1u);
  const Mesh& m = s.meshes[0];
  ASSERT_EQ(m.morph_deltas.size(), 2u);
  EXPECT_EQ(m.morph_deltas[0], kLift);
  EXPECT_EQ(m.morph_deltas[1], kWiden);
  EXPECT_EQ(m.morph_weights, (std::vector<float>{0.25f, 0.0f}));
  EXPECT_EQ(m.morph_base, kQuad);
  expect_positions(m.positions, {0.25f, 0.0f});  // the rest pose takes the default weights
  ASSERT_EQ(s.triangles.size(), 4u);
  EXPECT_FLOAT_EQ(s.triangles[0].v2.z, 0.25f);  // the flattened world triangles too
  for (const std::string& w : s.report.warnings) EXPECT_EQ(w.find("morph"), std::string::npos) << w;

  ASSERT_EQ(s.animations.size(), 1u);
  const AnimationChannel& c = s.animations[0].channels.at(0);
  EXPECT_EQ(c.path, P::weights);
  // Linear, by hand: t = 0.5 halfway from (0, 0) to (1, 0.5); t = 1.5 from (1, 0.5) to (0.5, 1).
  EXPECT_EQ(sample_weights(c, 0.5f), (std::vector<float>{0.5f, 0.25f}));
  EXPECT_EQ(sample_weights(c, 1.5f), (std::vector<float>{0.75f, 0.75f}));
  EXPECT_EQ(sample_weights(c, -1.0f), (std::vector<float>{0.0f, 0.0f}));  // clamped
  EXPECT_EQ(sample_weights(c, 9.0f), (std::vector<float>{0.5f, 1.0f}));

  EXPECT_TRUE(scene_animates(s));
  EXPECT_EQ(deforming_meshes(s), (std::vector<std::uint32_t>{0}));
  EXPECT_EQ(mesh_morph_weights(s, 0, 1.5f), (std::vector<float>{0.75f, 0.75f}));
  expect_positions(posed_positions(s, 0, 1.5f), {0.75f, 0.75f});
  // posed_scene: both instances show the morphed mesh, flattened again.
  const Scene at = posed_scene(s, 0.5f);
  expect_positions(at.meshes[0].positions, {0.5f, 0.25f});
  ASSERT_EQ(at.triangles.size(), 4u);
  EXPECT_FLOAT_EQ(at.triangles[2].v2.z, 0.5f);          // instance 1's copy of vertex 2
  EXPECT_FLOAT_EQ(at.triangles[2].v1.x, 3.0f + 1.25f);  // vertex 2 widened by 0.25, moved by 3
  const SceneEffects fx = decide_effects(s, {});
  EXPECT_TRUE(fx.per_frame_updates.on);
  EXPECT_NE(fx.per_frame_updates.reason.find("1 deforming mesh"), std::string::npos) << fx.per_frame_updates.reason;
}

TEST(MorphTargets, StepAndCubicWeightsByHand) {
  AnimationChannel step;
  step.path = P::weights;
  step.interpolation = I::step;
  step.times = {0.0f, 2.0f};
  step.values = {{0.2f, 0, 0, 0}, {0.4f, 0, 0, 0}, {0.6f, 0, 0, 0}, {0.8f, 0, 0, 0}};  // 2 keys x 2 targets
  EXPECT_EQ(sample_weights(step, 1.9f), (std::vector<float>{0.2f, 0.4f}));
  EXPECT_EQ(sample_weights(step, 2.0f), (std::vector<float>{0.6f, 0.8f}));

  // Cubic spline, 2 keys x 1 target: (in, value, out) per key; key interval 2 s.
  AnimationChannel cubic;
  cubic.path = P::weights;
  cubic.interpolation = I::cubic_spline;
  cubic.times = {1.0f, 3.0f};
  cubic.values = {{9, 0, 0, 0}, {0.0f, 0, 0, 0}, {0.5f, 0, 0, 0}, {-0.25f, 0, 0, 0}, {1.0f, 0, 0, 0}, {9, 0, 0, 0}};
  // t = 2: s = 0.5; h00 = 0.5, h10 = 0.125, h01 = 0.5, h11 = -0.125; tangents scaled by td = 2:
  // 0.5*0 + 2*0.125*0.5 + 0.5*1 + 2*(-0.125)*(-0.25) = 0.125 + 0.5 + 0.0625 = 0.6875.
  const std::vector<float> w = sample_weights(cubic, 2.0f);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NEAR(w[0], 0.6875f, 1e-6f);
  EXPECT_EQ(sample_weights(cubic, 3.0f), (std::vector<float>{1.0f}));

  AnimationChannel bad = cubic;
  bad.values.pop_back();
  EXPECT_THROW(sample_weights(bad, 2.0f), std::invalid_argument);
}

TEST(MorphTargets, WeightCountMismatchIsAOneLineError) {
  MorphGltf g = morph_quad_file();
  const int times = g.scalars({0.0f, 1.0f});
  // 6 values for 2 keys: 3 weights per key, but the mesh has 2 morph targets.
  const int three = g.scalars({0.0f, 0.0f, 0.0f, 1.0f, 1.0f, 1.0f});
  g.doc["animations"][0]["samplers"].push_back({{"input", times}, {"output", three}});
  g.doc["animations"][0]["channels"][0]["sampler"] = 1;
  const test_support::TempDir dir("morph");
  const std::string file = g.write(dir.path() / "bad.gltf");
  try {
    load_gltf(file);
    ADD_FAILURE() << "no error";
  } catch (const SceneError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(file + ": ", 0), 0u) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    EXPECT_NE(msg.find("6 weights for 2 keyframes of the 2 morph targets"), std::string::npos) << msg;
  }
}

/// A wavy grid (N x N quads) whose one morph target bumps it in z, and a
/// weights channel 0 -> 1 -> 0 over 2 s, instanced twice.
Scene morphing_grid(int n) {
  Scene s;
  Mesh m;
  m.name = "grid";
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) m.positions.emplace_back(float(x) / n, float(y) / n, 0.0f);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const std::uint32_t a = y * (n + 1) + x;
      m.indices.emplace_back(a, a + 1, a + n + 2);
      m.indices.emplace_back(a, a + n + 2, a + n + 1);
    }
  std::vector<glm::vec3> bump;
  for (const glm::vec3& p : m.positions)
    bump.emplace_back(0.3f * std::sin(7.0f * p.y), 0.0f, 0.8f * std::sin(9.0f * p.x) * std::cos(5.0f * p.y));
  m.morph_base = m.positions;
  m.morph_deltas = {bump};
  m.morph_weights = {0.0f};
  s.meshes.push_back(m);
  for (int i = 0; i < 2; ++i) {
    Node node;
    node.mesh = 0;
    node.translation = glm::vec3(1.5f * i, 0.0f, 0.0f);
    node.local = compose_trs(node.translation, node.rotation, node.scale);
    s.nodes.push_back(node);
    s.roots.push_back(i);
    Instance inst;
    inst.mesh = 0;
    inst.node = static_cast<std::uint32_t>(i);
    inst.transform = node.local;
    s.instances.push_back(inst);
  }
  AnimationChannel c;
  c.node = 0;
  c.path = P::weights;
  c.times = {0.0f, 1.0f, 2.0f};
  c.values = {{0, 0, 0, 0}, {1, 0, 0, 0}, {0, 0, 0, 0}};
  s.animations.push_back({"bump", {c}});
  s.flatten();
  return s;
}

TEST(MorphTargets, RefitThenQueryEqualsRebuildThenQuery) {
  const Scene s = morphing_grid(24);
  ASSERT_EQ(s.triangles.size(), 2u * 2 * 24 * 24);
  Tlas refitted(s);
  AnimatorOptions ao;
  ao.rebuild_ratio = 0.0;  // always refit
  SceneAnimator anim(s, refitted, ao);
  const Camera cam = look_at({1.2f, 0.5f, 1.6f}, {1.2f, 0.5f, 0.0f}, 0.9f);
  for (const float t : {0.35f, 1.0f, 1.6f}) {
    const FrameStats f = anim.step(t);
    EXPECT_EQ(f.refits, 1u) << t;
    EXPECT_EQ(f.rebuilds, 0u);
    EXPECT_EQ(f.moved_instances, 0u);  // weights move no node
    EXPECT_TRUE(f.tlas_rebuilt);
    // Deformed vertices: base + w * delta, w hand-computed from the keys.
    const float w = t <= 1.0f ? t : 2.0f - t;
    const std::vector<glm::vec3> p = posed_positions(s, 0, t);
    for (std::size_t i = 0; i < p.size(); i += 37)
      EXPECT_EQ(p[i], s.meshes[0].morph_base[i] + w * s.meshes[0].morph_deltas[0][i]) << "vertex " << i;
    // A fresh build over the posed scene answers the same, pixel by pixel.
    const Scene posed = posed_scene(s, t);
    const Tlas rebuilt(posed);
    const Bvh flat(posed.triangles);
    std::size_t hits = 0, differ = 0, flat_differ = 0;
    for (int y = 0; y < 40; ++y)
      for (int x = 0; x < 60; ++x) {
        const Ray r = primary_ray(cam, x, y, 60, 40);
        const Hit a = refitted.closest_hit(r, QueryOptions{});
        const Hit b = rebuilt.closest_hit(r, QueryOptions{});
        const Hit c = flat.closest_hit(r, QueryOptions{});
        hits += a.valid();
        differ += a.valid() != b.valid() || (a.valid() && a.t != b.t);
        // World-space triangles round differently from the instance transform: t within 1e-5.
        // (a ray grazing an edge may fall either way between the two spaces: at most a couple).
        flat_differ += a.valid() != c.valid() || (a.valid() && c.valid() && std::abs(a.t - c.t) > 1e-5f);
      }
    EXPECT_EQ(differ, 0u) << "t = " << t;
    EXPECT_LE(flat_differ, 2u) << "t = " << t;
    EXPECT_GT(hits, 600u);
  }
  // Past the ratio the BLAS is rebuilt instead, with the same answers.
  Tlas eager(s);
  AnimatorOptions always;
  always.rebuild_ratio = 1.0 + 1e-12;
  SceneAnimator b(s, eager, always);
  std::uint32_t rebuilds = 0;
  for (int i = 1; i <= 4; ++i) rebuilds += b.step(0.25f * i).rebuilds;
  EXPECT_GT(rebuilds, 0u);
}

}  // namespace unity_test_morph_targets
