// write_gltf: round trips through load_gltf, the file layout, and refusals.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>

#include "core/scene/gltf_writer.h"
#include "core/scene/load.h"
#include "tests/support/temp_dir.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_gltf_writer {

using namespace accelviz;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

using test_support::read_file;

std::uint32_t u32_at(const std::string& s, std::size_t offset) {
  std::uint32_t v;
  std::memcpy(&v, s.data() + offset, 4);
  return v;
}

void expect_vec3_near(const glm::vec3& a, const glm::vec3& b, float eps = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, eps);
  EXPECT_NEAR(a.y, b.y, eps);
  EXPECT_NEAR(a.z, b.z, eps);
}

void expect_same_triangles(const Scene& a, const Scene& b) {
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  for (std::size_t i = 0; i < a.triangles.size(); ++i) {
    EXPECT_EQ(a.triangles[i].v0, b.triangles[i].v0) << "triangle " << i;
    EXPECT_EQ(a.triangles[i].v1, b.triangles[i].v1) << "triangle " << i;
    EXPECT_EQ(a.triangles[i].v2, b.triangles[i].v2) << "triangle " << i;
  }
}

/// A scene as the loader would produce it: a two-level hierarchy with TRS and
/// matrix nodes, a mesh used twice, a second mesh, a camera and two lights.
Scene sample_scene() {
  Scene s;
  Mesh quad;
  quad.name = "quad";
  quad.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  quad.indices = {{0, 1, 2}, {0, 2, 3}};
  Mesh tri;
  tri.name = "tri";
  tri.positions = {{0, 0, 0}, {0.1f, 0, 0}, {0, 0.3f, 0.7f}};
  tri.indices = {{0, 1, 2}};
  s.meshes = {quad, tri};

  Node root;
  root.name = "root";
  root.translation = {1, 2, 3};
  root.rotation = glm::angleAxis(0.3f, glm::normalize(glm::vec3(1, 1, 0)));
  root.scale = {2, 2, 2};
  root.local = glm::translate(glm::mat4(1.0f), root.translation) * glm::mat4_cast(root.rotation) *
               glm::scale(glm::mat4(1.0f), root.scale);
  root.children = {1, 2};
  root.mesh = 0;
  Node child;
  child.name = "child";
  child.parent = 0;
  child.has_matrix = true;
  child.local =
      glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, 4)) * glm::rotate(glm::mat4(1.0f), 1.0f, glm::vec3(0, 1, 0));
  child.mesh = 0;
  Node other;
  other.parent = 0;
  other.translation = {-3, 0, 0};
  other.local = glm::translate(glm::mat4(1.0f), other.translation);
  other.mesh = 1;
  s.nodes = {root, child, other};
  s.roots = {0};
  const glm::mat4 w0 = root.local, w1 = root.local * child.local, w2 = root.local * other.local;
  s.instances = {{0, 0, w0}, {0, 1, w1}, {1, 2, w2}};

  Camera cam;
  cam.name = "view";
  cam.position = {0, 1, 8};
  cam.forward = glm::normalize(glm::vec3(0, -0.2f, -1));
  cam.up = glm::normalize(glm::cross(glm::cross(cam.forward, glm::vec3(0, 1, 0)), cam.forward));
  cam.yfov = 0.7f;
  cam.aspect = 1.25f;
  s.cameras = {cam};
  Light sun;
  sun.kind = Light::Kind::directional;
  sun.direction = glm::normalize(glm::vec3(1, -1, 0));
  sun.intensity = 3;
  Light lamp;
  lamp.name = "lamp";
  lamp.kind = Light::Kind::spot;
  lamp.position = {0, 4, 0};
  lamp.direction = {0, -1, 0};
  lamp.color = {1, 0.5f, 0};
  lamp.range = 9;
  lamp.inner_cone = 0.1f;  // the cone is written as it was read (it was written as {}: glTF's defaults)
  lamp.outer_cone = 0.3f;
  s.lights = {sun, lamp};
  s.flatten();
  return s;
}

class GltfWriter : public test_support::TempDirTest {};

TEST_F(GltfWriter, RoundTripGlbGivesTheSameTriangles) {
  const Scene original = sample_scene();
  ASSERT_EQ(original.triangles.size(), 5u);
  write_gltf(original, path("out.glb"), true);
  const Scene back = load_gltf(path("out.glb"));
  expect_same_triangles(original, back);
  ASSERT_EQ(back.instances.size(), 3u);
  EXPECT_TRUE(back.has_instancing());
  EXPECT_EQ(back.meshes[0].name, "quad");
  EXPECT_EQ(back.nodes[0].name, "root");
  EXPECT_TRUE(back.nodes[1].has_matrix);
  EXPECT_FALSE(back.nodes[0].has_matrix);
  EXPECT_EQ(back.nodes[0].children, (std::vector<int>{1, 2}));
}

TEST_F(GltfWriter, RoundTripGltfKeepsCamerasAndLights) {
  const Scene original = sample_scene();
  write_gltf(original, path("out.gltf"), false);
  const Scene back = load_gltf(path("out.gltf"));
  expect_same_triangles(original, back);

  ASSERT_EQ(back.cameras.size(), 1u);
  const Camera& c = back.cameras[0];
  EXPECT_EQ(c.name, "view");
  expect_vec3_near(c.position, original.cameras[0].position);
  expect_vec3_near(c.forward, original.cameras[0].forward);
  expect_vec3_near(c.up, original.cameras[0].up);
  EXPECT_FLOAT_EQ(c.yfov, 0.7f);
  EXPECT_FLOAT_EQ(c.aspect, 1.25f);

  ASSERT_EQ(back.lights.size(), 2u);
  EXPECT_EQ(back.lights[0].kind, Light::Kind::directional);
  expect_vec3_near(back.lights[0].direction, original.lights[0].direction);
  EXPECT_FLOAT_EQ(back.lights[0].intensity, 3.0f);
  EXPECT_EQ(back.lights[1].kind, Light::Kind::spot);
  EXPECT_EQ(back.lights[1].name, "lamp");
  expect_vec3_near(back.lights[1].position, {0, 4, 0});
  expect_vec3_near(back.lights[1].direction, {0, -1, 0});
  expect_vec3_near(back.lights[1].color, {1, 0.5f, 0});
  EXPECT_FLOAT_EQ(back.lights[1].range, 9.0f);
  EXPECT_FLOAT_EQ(back.lights[1].inner_cone, 0.1f);
  EXPECT_FLOAT_EQ(back.lights[1].outer_cone, 0.3f);
  // The widest cone glTF allows, pi/2, survives a round trip (as a float it lies above pi/2 as a double).
  Scene wide = original;
  wide.lights[1].inner_cone = 1.5f;
  wide.lights[1].outer_cone = 1.5707963267948966f;
  write_gltf(wide, path("wide_cone.gltf"), false);
  const Scene wide_back = load_gltf(path("wide_cone.gltf"));
  ASSERT_EQ(wide_back.lights.size(), 2u);
  EXPECT_FLOAT_EQ(wide_back.lights[1].outer_cone, 1.5707963267948966f);
  EXPECT_FLOAT_EQ(wide_back.lights[1].inner_cone, 1.5f);
  EXPECT_TRUE(wide_back.report.warnings.empty()) << wide_back.report.warnings.front();
}

TEST_F(GltfWriter, RoundTripOfALoadedFileIsStable) {
  // load -> write -> load -> write: the second file equals the first.
  write_gltf(sample_scene(), path("a.glb"), true);
  const Scene first = load_gltf(path("a.glb"));
  write_gltf(first, path("b.glb"), true);
  const Scene second = load_gltf(path("b.glb"));
  expect_same_triangles(first, second);
  write_gltf(second, path("c.glb"), true);
  // Cameras and lights are re-emitted as fresh root nodes each time, so only
  // the geometry-carrying part is compared byte for byte: same size and same
  // BIN chunk.
  const std::string b = read_file(dir_ / "b.glb"), c = read_file(dir_ / "c.glb");
  const std::size_t bin_b = 20 + u32_at(b, 12), bin_c = 20 + u32_at(c, 12);
  EXPECT_EQ(b.substr(bin_b), c.substr(bin_c));
}

TEST_F(GltfWriter, InstancesWithoutNodesBecomeRootNodes) {
  // Generators may fill meshes and instances only.
  Scene s;
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.indices = {{0, 1, 2}};
  s.meshes = {m};
  for (int k = 0; k < 3; ++k) {
    Instance inst;
    inst.mesh = 0;
    inst.transform = glm::translate(glm::mat4(1.0f), glm::vec3(float(k) * 2.5f, 0, 0)) *
                     glm::rotate(glm::mat4(1.0f), 0.4f * float(k), glm::vec3(0, 0, 1));
    s.instances.push_back(inst);
  }
  s.flatten();
  write_gltf(s, path("inst.glb"), true);
  const Scene back = load_gltf(path("inst.glb"));
  expect_same_triangles(s, back);
  EXPECT_EQ(back.instances.size(), 3u);
  EXPECT_EQ(back.nodes.size(), 3u);
  EXPECT_TRUE(back.has_instancing());
}

TEST_F(GltfWriter, InstanceThatDisagreesWithItsNodeGetsItsOwnNode) {
  Scene s = sample_scene();
  // Move the second instance away from where its node would put it.
  s.instances[1].transform = glm::translate(glm::mat4(1.0f), glm::vec3(50, 0, 0));
  s.flatten();
  write_gltf(s, path("moved.glb"), true);
  const Scene back = load_gltf(path("moved.glb"));
  ASSERT_EQ(back.triangles.size(), s.triangles.size());
  // Its triangles come last now (an extra root node); all the others keep their order.
  EXPECT_EQ(back.triangles[0].v0, s.triangles[0].v0);
  EXPECT_EQ(back.triangles[2].v0, s.triangles[4].v0);
  EXPECT_EQ(back.triangles[3].v0, s.triangles[2].v0);
  EXPECT_EQ(back.triangles[4].v2, s.triangles[3].v2);
}

TEST_F(GltfWriter, GlbLayoutAndAccessorBounds) {
  write_gltf(sample_scene(), path("layout.glb"), true);
  const std::string bytes = read_file(dir_ / "layout.glb");
  ASSERT_GE(bytes.size(), 28u);
  EXPECT_EQ(bytes.substr(0, 4), "glTF");
  EXPECT_EQ(u32_at(bytes, 4), 2u);
  EXPECT_EQ(u32_at(bytes, 8), bytes.size());
  const std::uint32_t json_length = u32_at(bytes, 12);
  EXPECT_EQ(json_length % 4, 0u);
  EXPECT_EQ(u32_at(bytes, 16), 0x4E4F534Au);
  const std::size_t bin = 20 + json_length;
  EXPECT_EQ(u32_at(bytes, bin + 4), 0x004E4942u);
  EXPECT_EQ(u32_at(bytes, bin) % 4, 0u);
  EXPECT_EQ(bin + 8 + u32_at(bytes, bin), bytes.size());

  const json doc = json::parse(bytes.substr(20, json_length));
  EXPECT_EQ(doc["asset"]["version"], "2.0");
  const json& pos = doc["accessors"][0];
  EXPECT_EQ(pos["componentType"], 5126);
  EXPECT_EQ(pos["type"], "VEC3");
  EXPECT_EQ(pos["min"], json({0.0, 0.0, 0.0}));
  EXPECT_EQ(pos["max"], json({1.0, 1.0, 0.0}));
  const json& idx = doc["accessors"][1];
  EXPECT_EQ(idx["componentType"], 5125);
  EXPECT_EQ(idx["count"], 6);
  EXPECT_EQ(idx["min"], json::array({0}));
  EXPECT_EQ(idx["max"], json::array({3}));
  EXPECT_EQ(doc["extensionsUsed"], json({"KHR_lights_punctual"}));
}

TEST_F(GltfWriter, NonFinitePositionsAreWrittenButLeftOutOfMinMax) {
  Scene s;
  Mesh m;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {nan, 5, 5}};
  m.indices = {{0, 1, 2}, {0, 1, 3}};
  s.meshes = {m};
  s.instances = {Instance{}};
  s.flatten();
  write_gltf(s, path("nan.gltf"), false);
  const json doc = json::parse(read_file(dir_ / "nan.gltf"));
  EXPECT_EQ(doc["accessors"][0]["max"], json({1.0, 1.0, 0.0}));
  const Scene back = load_gltf(path("nan.gltf"));
  EXPECT_EQ(back.triangles.size(), 1u);
  EXPECT_EQ(back.report.dropped_nonfinite, 1u);
}

TEST_F(GltfWriter, RefusesToOverwriteUnlessAsked) {
  const Scene s = sample_scene();
  write_gltf(s, path("x.glb"), true);
  const std::string before = read_file(dir_ / "x.glb");
  Scene smaller = s;
  smaller.instances.resize(1);
  smaller.flatten();
  try {
    write_gltf(smaller, path("x.glb"), true);
    ADD_FAILURE() << "overwrote an existing file";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()), path("x.glb") + ": exists (use --force to overwrite)");
  }
  EXPECT_EQ(read_file(dir_ / "x.glb"), before);
  write_gltf(smaller, path("x.glb"), true, /*overwrite=*/true);
  EXPECT_EQ(load_gltf(path("x.glb")).triangles.size(), 2u);
  EXPECT_FALSE(fs::exists(dir_ / "x.glb.part"));
}

TEST_F(GltfWriter, UnwritableDirectoryIsASceneError) {
  const std::string target = path("no/such/dir/out.glb");
  try {
    write_gltf(sample_scene(), target, true);
    ADD_FAILURE() << "wrote into a missing directory";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(target + ": cannot create: No such file or directory", 0), 0u) << e.what();
  }
}

TEST_F(GltfWriter, InvalidNodeGraphIsRefused) {
  // The loader would reject these files, so the writer does not produce them.
  auto expect_refused = [&](const Scene& s, const std::string& name, const std::string& problem) {
    try {
      write_gltf(s, path(name), true);
      ADD_FAILURE() << "wrote " << name;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(problem), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir_ / name));
  };
  Scene cycle = sample_scene();
  cycle.nodes[2].children = {0};  // 0 -> 2 -> 0
  expect_refused(cycle, "cycle.glb", "node graph has a cycle");
  Scene two_parents = sample_scene();
  two_parents.nodes[1].children = {2};  // node 2 is also a child of node 0
  expect_refused(two_parents, "parents.glb", "node 2 has more than one parent");
  Scene self = sample_scene();
  self.nodes[2].children = {2};
  expect_refused(self, "self.glb", "node 2 has invalid child 2");
}

}  // namespace
}  // namespace unity_test_gltf_writer
