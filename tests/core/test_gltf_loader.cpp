// load_gltf: every fixture is written by the test into its own temp directory.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/scene/load.h"
#include "tests/core/base64.h"
#include "tests/support/temp_dir.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_gltf_loader {

using namespace accelviz;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

constexpr int kU8 = 5121, kU16 = 5123, kU32 = 5125, kFloat = 5126;

/// Whether a loader warning of `s` contains `part`.
bool warned(const Scene& s, const std::string& part) {
  return std::any_of(s.report.warnings.begin(), s.report.warnings.end(),
                     [&](const std::string& w) { return w.find(part) != std::string::npos; });
}

void put_u32(std::string& s, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) s += char((v >> (8 * k)) & 0xFF);
}

/// Builds glTF documents in memory: one buffer, views appended 4-aligned.
struct GltfBuilder {
  json doc = {{"asset", {{"version", "2.0"}}}};
  std::vector<unsigned char> bin;

  int view(const void* data, std::size_t bytes, std::size_t stride = 0) {
    while (bin.size() % 4) bin.push_back(0);
    const std::size_t offset = bin.size();
    bin.resize(offset + bytes);
    std::memcpy(bin.data() + offset, data, bytes);
    json v = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}};
    if (stride) v["byteStride"] = stride;
    doc["bufferViews"].push_back(v);
    return int(doc["bufferViews"].size() - 1);
  }
  int accessor(int view, int component_type, std::size_t count, const char* type, std::size_t offset = 0) {
    json a = {{"bufferView", view}, {"componentType", component_type}, {"count", count}, {"type", type}};
    if (offset) a["byteOffset"] = offset;
    doc["accessors"].push_back(a);
    return int(doc["accessors"].size() - 1);
  }
  int positions(const std::vector<glm::vec3>& p) {
    return accessor(view(p.data(), p.size() * sizeof(glm::vec3)), kFloat, p.size(), "VEC3");
  }
  template <class T>
  int indices(const std::vector<T>& idx, int component_type) {
    return accessor(view(idx.data(), idx.size() * sizeof(T)), component_type, idx.size(), "SCALAR");
  }
  int floats(const std::vector<float>& f, const char* type, std::size_t per) {
    return accessor(view(f.data(), f.size() * sizeof(float)), kFloat, f.size() / per, type);
  }
  json primitive(int pos, int idx = -1, int mode = -1) {
    json p = {{"attributes", {{"POSITION", pos}}}};
    if (idx >= 0) p["indices"] = idx;
    if (mode >= 0) p["mode"] = mode;
    return p;
  }
  int mesh(std::vector<json> primitives) {
    doc["meshes"].push_back({{"primitives", primitives}});
    return int(doc["meshes"].size() - 1);
  }
  int node(json n) {
    doc["nodes"].push_back(std::move(n));
    return int(doc["nodes"].size() - 1);
  }
  void scene(std::vector<int> roots) {
    doc["scenes"] = json::array({json{{"nodes", roots}}});
    doc["scene"] = 0;
  }

  std::string gltf_text() const {
    json d = doc;
    if (!bin.empty())
      d["buffers"] = json::array(
          {json{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + test::base64(bin)}}});
    return d.dump(1);
  }
  std::string glb_bytes() const {
    json d = doc;
    std::vector<unsigned char> b = bin;
    while (b.size() % 4) b.push_back(0);
    if (!b.empty()) d["buffers"] = json::array({json{{"byteLength", bin.size()}}});
    std::string js = d.dump();
    while (js.size() % 4) js += ' ';
    std::string out;
    put_u32(out, 0x46546C67);
    put_u32(out, 2);
    put_u32(out, std::uint32_t(12 + 8 + js.size() + (b.empty() ? 0 : 8 + b.size())));
    put_u32(out, std::uint32_t(js.size()));
    put_u32(out, 0x4E4F534A);
    out += js;
    if (!b.empty()) {
      put_u32(out, std::uint32_t(b.size()));
      put_u32(out, 0x004E4942);
      out.append(reinterpret_cast<const char*>(b.data()), b.size());
    }
    return out;
  }
};

void write_file(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), std::streamsize(bytes.size()));
  ASSERT_TRUE(out.good()) << path;
}

/// One triangle: (0,0,0), (1,0,0), (0,1,0), indexed with u16.
GltfBuilder one_triangle() {
  GltfBuilder b;
  const int pos = b.positions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  const int idx = b.indices<std::uint16_t>({0, 1, 2}, kU16);
  b.mesh({b.primitive(pos, idx)});
  b.node({{"mesh", 0}});
  b.scene({0});
  return b;
}

/// A unit quad in z=0 as two triangles.
int quad_mesh(GltfBuilder& b) {
  const int pos = b.positions({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}});
  const int idx = b.indices<std::uint32_t>({0, 1, 2, 0, 2, 3}, kU32);
  return b.mesh({b.primitive(pos, idx)});
}

void expect_vec3_near(const glm::vec3& a, const glm::vec3& b, float eps = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, eps);
  EXPECT_NEAR(a.y, b.y, eps);
  EXPECT_NEAR(a.z, b.z, eps);
}

class GltfLoader : public test_support::TempDirTest {
 protected:
  std::string write_gltf(const GltfBuilder& b, const std::string& name = "scene.gltf") {
    write_file(dir_ / name, b.gltf_text());
    return path(name);
  }
  std::string write_glb(const GltfBuilder& b, const std::string& name = "scene.glb") {
    write_file(dir_ / name, b.glb_bytes());
    return path(name);
  }

  /// one_triangle() as a .gltf whose buffer is the external file `uri`.
  std::string write_gltf_with_buffer_uri(const std::string& uri, const std::string& name = "external.gltf") {
    const GltfBuilder b = one_triangle();
    json d = b.doc;
    d["buffers"] = json::array({json{{"byteLength", b.bin.size()}, {"uri", uri}}});
    write_file(dir_ / name, d.dump());
    return path(name);
  }

  /// Loads `file`, expecting a SceneError that names the file, contains
  /// `problem` and is a single line.
  void expect_error(const std::string& file, const std::string& problem) {
    try {
      load_gltf(file);
      ADD_FAILURE() << "no error loading " << file << " (expected '" << problem << "')";
    } catch (const SceneError& e) {
      const std::string msg = e.what();
      RecordProperty("message", msg);  // visible with --gtest_output=xml
      EXPECT_EQ(msg.rfind(file + ": ", 0), 0u) << msg;
      EXPECT_NE(msg.find(problem), std::string::npos) << "message: " << msg << "\nexpected: " << problem;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
  }
};

// --- valid files -------------------------------------------------------------

TEST_F(GltfLoader, MinimalGltfWithEmbeddedBuffer) {
  const std::string file = write_gltf(one_triangle());
  const Scene s = load_gltf(file);
  EXPECT_EQ(s.source, file);
  ASSERT_EQ(s.triangles.size(), 1u);
  expect_vec3_near(s.triangles[0].v0, {0, 0, 0});
  expect_vec3_near(s.triangles[0].v1, {1, 0, 0});
  expect_vec3_near(s.triangles[0].v2, {0, 1, 0});
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].positions.size(), 3u);
  ASSERT_EQ(s.instances.size(), 1u);
  EXPECT_EQ(s.roots, std::vector<int>{0});
  EXPECT_FALSE(s.has_instancing());
  EXPECT_EQ(s.report.dropped_nonfinite, 0u);
  EXPECT_EQ(s.report.degenerate, 0u);
}

TEST_F(GltfLoader, MinimalGlb) {
  const Scene s = load_gltf(write_glb(one_triangle()));
  ASSERT_EQ(s.triangles.size(), 1u);
  const Aabb box = s.bounds();
  expect_vec3_near(box.lo, {0, 0, 0});
  expect_vec3_near(box.hi, {1, 1, 0});
}

TEST_F(GltfLoader, UppercaseExtensionAndBinaryContentSniffed) {
  // A GLB under a .GLTF name loads: the magic decides, not the extension.
  const Scene s = load_gltf(write_glb(one_triangle(), "SCENE.GLTF"));
  EXPECT_EQ(s.triangles.size(), 1u);
}

TEST_F(GltfLoader, TwoNodesSharingAMeshBecomeInstances) {
  GltfBuilder b;
  quad_mesh(b);
  b.node({{"mesh", 0}, {"translation", {10, 0, 0}}});
  b.node({{"mesh", 0}, {"translation", {-10, 0, 5}}});
  b.scene({0, 1});
  const Scene s = load_gltf(write_gltf(b));
  ASSERT_EQ(s.meshes.size(), 1u);
  ASSERT_EQ(s.instances.size(), 2u);
  EXPECT_TRUE(s.has_instancing());
  ASSERT_EQ(s.triangles.size(), 4u);  // 2 triangles x 2 instances
  EXPECT_EQ(s.instances[0].first_triangle, 0u);
  EXPECT_EQ(s.instances[0].triangle_count, 2u);
  EXPECT_EQ(s.instances[1].first_triangle, 2u);
  expect_vec3_near(s.triangles[0].v0, {10, 0, 0});
  expect_vec3_near(s.triangles[0].v2, {11, 1, 0});
  expect_vec3_near(s.triangles[2].v0, {-10, 0, 5});
  // The mesh itself stays in object space.
  expect_vec3_near(s.meshes[0].positions[0], {0, 0, 0});
}

// glTF 2.0 forbids a matrix beside TRS: the matrix wins (tinygltf then skips the TRS), and a warning
// says so (it was silent).
TEST_F(GltfLoader, AMatrixBesideTrsIsUsedAndWarnedAbout) {
  GltfBuilder b;
  quad_mesh(b);
  b.node({{"mesh", 0}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 5, 0, 0, 1}}, {"translation", {0, 7, 0}}});
  b.node({{"mesh", 0}, {"translation", {0, 7, 0}}, {"extras", {{"matrix", 1}}}});  // extras' keys are not the node's
  b.scene({0, 1});
  const Scene s = load_gltf(write_gltf(b));
  ASSERT_EQ(s.triangles.size(), 4u);
  expect_vec3_near(s.triangles[0].v0, {5, 0, 0});
  std::string all;
  for (const std::string& w : s.report.warnings) all += w + "\n";
  EXPECT_NE(all.find("node 0 has both a matrix and translation/rotation/scale"), std::string::npos) << all;
  EXPECT_EQ(all.find("node 1"), std::string::npos) << all;
}

// World transforms are composed in double: a chain of 1,000 nodes each moved
// by 0.001 put its mesh at z = 0.99899 in float, not 1.
TEST_F(GltfLoader, ADeepChainOfSmallMovesLandsWhereItsSumSays) {
  GltfBuilder b;
  quad_mesh(b);
  constexpr int kDepth = 1000;
  for (int k = 0; k < kDepth; ++k) {
    json n = {{"translation", {0, 0, 0.001}}};
    if (k + 1 < kDepth)
      n["children"] = {k + 1};
    else
      n["mesh"] = 0;
    b.node(n);
  }
  b.scene({0});
  const Scene s = load_gltf(write_gltf(b));
  ASSERT_EQ(s.triangles.size(), 2u);
  EXPECT_NEAR(s.triangles[0].v0.z, 1.0f, 1e-5f);
}

// Files that are valid JSON but not what glTF 2.0 allows are loaded with a
// warning that says what was assumed, not silently.
TEST_F(GltfLoader, ProjectiveMatrixAndOtherAssetVersionsAreWarnedAbout) {
  const auto warnings_of = [](const Scene& s) {
    std::string all;
    for (const std::string& w : s.report.warnings) all += w + "|";
    return all;
  };
  GltfBuilder b = one_triangle();
  EXPECT_EQ(warnings_of(load_gltf(write_gltf(b, "plain.gltf"))), "");
  b.doc["asset"]["version"] = "3.0";
  b.doc["nodes"][0]["matrix"] = {1, 0, 0, 0.5, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};  // column 0 row 3: projective
  const std::string w = warnings_of(load_gltf(write_gltf(b, "odd.gltf")));
  EXPECT_NE(w.find("asset.version is '3.0', not 2.x; read as glTF 2.0"), std::string::npos) << w;
  EXPECT_NE(w.find("node 0 has a matrix whose last row is not (0, 0, 0, 1)"), std::string::npos) << w;
}

// A mesh's default weights without morph targets are ignored, and said so.
TEST_F(GltfLoader, MeshWeightsWithoutMorphTargetsAreWarnedAbout) {
  GltfBuilder b = one_triangle();
  b.doc["meshes"][0]["weights"] = {0.5, 0.25};
  const Scene s = load_gltf(write_gltf(b));
  ASSERT_EQ(s.triangles.size(), 1u);
  ASSERT_EQ(s.report.warnings.size(), 1u);
  EXPECT_EQ(s.report.warnings[0], "mesh 0 has 2 default morph weights but no morph targets; ignored");
}

// tinygltf reads `"rotation": "abc"` as no rotation and skips a string inside
// a matrix (then reporting 15 numbers): the pre-pass names the node, the
// property and the item instead.
TEST_F(GltfLoader, NonNumbersInNodeAndMeshArraysAreNamed) {
  const auto with = [&](const char* owner, const char* key, const json& value, const std::string& name) {
    GltfBuilder b = one_triangle();
    b.doc[owner][0][key] = value;
    return write_gltf(b, name);
  };
  expect_error(with("nodes", "rotation", "abc", "rot.gltf"),
               "invalid glTF: node 0: \"rotation\" is not an array of numbers");
  expect_error(with("nodes", "scale", json{{"x", 1}}, "scale.gltf"), "node 0: \"scale\" is not an array of numbers");
  expect_error(with("nodes", "matrix", json{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, "x", 1}, "matrix.gltf"),
               "invalid glTF: node 0: \"matrix\" has a non-number at item 14");
  expect_error(with("nodes", "translation", json{1, nullptr, 3}, "null.gltf"),
               "node 0: \"translation\" has a non-number at item 1");
  // json::array, not json{json{1}}: Clang reads that as a copy of [1].
  expect_error(with("nodes", "weights", json::array({json::array({1})}), "nested.gltf"),
               "node 0: \"weights\" has a non-number at item 0");
  expect_error(with("meshes", "weights", "w", "mesh.gltf"), "mesh 0: \"weights\" is not an array of numbers");
  // The node is counted past nested values before it.
  GltfBuilder c = one_triangle();
  c.doc["nodes"][0]["extras"] = {{"list", {1, {{"rotation", "not a node's"}}, {2, 3}}}};
  c.doc["nodes"].push_back({{"extras", {{"a", {{1, 2}, {3}}}}}, {"rotation", {0, 0, "z", 1}}});
  expect_error(write_gltf(c, "second.gltf"), "node 1: \"rotation\" has a non-number at item 2");
  // The same keys elsewhere are not nodes' transforms and stay tinygltf's business.
  GltfBuilder b = one_triangle();
  b.doc["asset"]["extras"] = {{"rotation", "abc"}, {"matrix", {"x"}}};
  EXPECT_EQ(load_gltf(write_gltf(b, "extras.gltf")).triangles.size(), 1u);
}

TEST_F(GltfLoader, TrsAndMatrixGiveTheSameWorldTriangles) {
  const glm::vec3 t(1, 2, 3), sc(2, 2, 2);
  const glm::quat r = glm::angleAxis(glm::radians(90.0f), glm::vec3(0, 0, 1));
  const glm::mat4 m = glm::translate(glm::mat4(1.0f), t) * glm::mat4_cast(r) * glm::scale(glm::mat4(1.0f), sc);
  std::vector<double> matrix;
  for (int c = 0; c < 4; ++c)
    for (int k = 0; k < 4; ++k) matrix.push_back(m[c][k]);

  GltfBuilder b;
  quad_mesh(b);
  b.node({{"mesh", 0}, {"translation", {t.x, t.y, t.z}}, {"rotation", {r.x, r.y, r.z, r.w}}, {"scale", {2, 2, 2}}});
  b.node({{"mesh", 0}, {"matrix", matrix}});
  b.scene({0, 1});
  const Scene s = load_gltf(write_gltf(b));
  ASSERT_EQ(s.triangles.size(), 4u);
  for (int k = 0; k < 2; ++k) {
    expect_vec3_near(s.triangles[std::size_t(k)].v0, s.triangles[std::size_t(k) + 2].v0);
    expect_vec3_near(s.triangles[std::size_t(k)].v1, s.triangles[std::size_t(k) + 2].v1);
    expect_vec3_near(s.triangles[std::size_t(k)].v2, s.triangles[std::size_t(k) + 2].v2);
  }
  // (1,0,0) rotated 90 degrees about z, scaled by 2, moved by t.
  expect_vec3_near(s.triangles[0].v1, {1, 4, 3});
  EXPECT_FALSE(s.nodes[0].has_matrix);
  EXPECT_TRUE(s.nodes[1].has_matrix);
  // The matrix node is decomposed for display.
  expect_vec3_near(s.nodes[1].translation, t);
  expect_vec3_near(s.nodes[1].scale, sc);
  EXPECT_NEAR(std::fabs(glm::dot(s.nodes[1].rotation, r)), 1.0f, 1e-5f);
}

TEST_F(GltfLoader, ChildWorldIsParentTimesLocal) {
  GltfBuilder b;
  const int pos = b.positions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  b.mesh({b.primitive(pos)});
  b.node({{"children", {1}}, {"scale", {2, 2, 2}}, {"translation", {0, 0, 7}}});
  b.node({{"mesh", 0}, {"translation", {1, 0, 0}}});
  b.scene({0});
  const Scene s = load_gltf(write_gltf(b));
  ASSERT_EQ(s.triangles.size(), 1u);
  expect_vec3_near(s.triangles[0].v0, {2, 0, 7});
  expect_vec3_near(s.triangles[0].v1, {4, 0, 7});
  EXPECT_EQ(s.nodes[1].parent, 0);
  EXPECT_EQ(s.nodes[0].children, std::vector<int>{1});
  EXPECT_EQ(s.instances[0].node, 1u);
}

TEST_F(GltfLoader, PrimitiveIdsFollowDepthFirstNodeOrder) {
  GltfBuilder b;
  for (int k = 0; k < 3; ++k) {  // mesh k lies in the plane z = k
    const float z = float(k);
    const int pos = b.positions({{0, 0, z}, {1, 0, z}, {0, 1, z}});
    b.mesh({b.primitive(pos)});
  }
  b.node({{"mesh", 0}});
  b.node({{"mesh", 1}});
  b.node({{"mesh", 2}, {"children", {1}}});
  b.scene({2, 0});  // roots in this order: node 2 (then its child 1), node 0
  const Scene s = load_gltf(write_gltf(b));
  ASSERT_EQ(s.triangles.size(), 3u);
  EXPECT_FLOAT_EQ(s.triangles[0].v0.z, 2.0f);
  EXPECT_FLOAT_EQ(s.triangles[1].v0.z, 1.0f);
  EXPECT_FLOAT_EQ(s.triangles[2].v0.z, 0.0f);
  EXPECT_EQ(s.roots, (std::vector<int>{2, 0}));
}

TEST_F(GltfLoader, WithoutScenesEveryParentlessNodeIsARoot) {
  GltfBuilder b = one_triangle();
  b.doc.erase("scenes");
  b.doc.erase("scene");
  b.node({{"mesh", 0}, {"translation", {5, 0, 0}}});
  const Scene s = load_gltf(write_gltf(b));
  EXPECT_EQ(s.roots, (std::vector<int>{0, 1}));
  EXPECT_EQ(s.triangles.size(), 2u);
}

TEST_F(GltfLoader, AllTrianglePrimitivesOfAMeshAreMerged) {
  GltfBuilder b;
  const int p0 = b.positions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  const int p1 = b.positions({{0, 0, 1}, {1, 0, 1}, {0, 1, 1}});
  b.mesh({b.primitive(p0), b.primitive(p1)});
  b.node({{"mesh", 0}});
  const Scene s = load_gltf(write_gltf(b));
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].positions.size(), 6u);
  ASSERT_EQ(s.meshes[0].indices.size(), 2u);
  EXPECT_EQ(s.meshes[0].indices[1], glm::uvec3(3, 4, 5));
  EXPECT_FLOAT_EQ(s.triangles[1].v0.z, 1.0f);
}

TEST_F(GltfLoader, TriangleStripUnrollsWithAlternatingWinding) {
  GltfBuilder b;
  std::vector<glm::vec3> v;
  for (int i = 0; i < 5; ++i) v.emplace_back(float(i), float(i % 2), 0.0f);
  const int pos = b.positions(v);
  b.mesh({b.primitive(pos, -1, 5)});
  b.node({{"mesh", 0}});
  const Scene s = load_gltf(write_gltf(b));
  ASSERT_EQ(s.meshes[0].indices.size(), 3u);
  EXPECT_EQ(s.meshes[0].indices[0], glm::uvec3(0, 1, 2));
  EXPECT_EQ(s.meshes[0].indices[1], glm::uvec3(1, 3, 2));
  EXPECT_EQ(s.meshes[0].indices[2], glm::uvec3(2, 3, 4));
  // Consistent winding: every normal points the same way (+z or -z).
  for (const Triangle& t : s.triangles) EXPECT_LT(t.cross_normal().z, 0.0f);
}

TEST_F(GltfLoader, IndexedTriangleFan) {
  GltfBuilder b;
  const int pos = b.positions({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {-1, 1, 0}});
  const int idx = b.indices<std::uint8_t>({0, 1, 2, 3, 4}, kU8);
  b.mesh({b.primitive(pos, idx, 6)});
  b.node({{"mesh", 0}});
  const Scene s = load_gltf(write_gltf(b));
  ASSERT_EQ(s.meshes[0].indices.size(), 3u);
  EXPECT_EQ(s.meshes[0].indices[0], glm::uvec3(1, 2, 0));
  EXPECT_EQ(s.meshes[0].indices[1], glm::uvec3(2, 3, 0));
  EXPECT_EQ(s.meshes[0].indices[2], glm::uvec3(3, 4, 0));
}

TEST_F(GltfLoader, NonIndexedTriangles) {
  GltfBuilder b;
  const int pos = b.positions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}});
  b.mesh({b.primitive(pos)});
  b.node({{"mesh", 0}});
  const Scene s = load_gltf(write_gltf(b));
  ASSERT_EQ(s.triangles.size(), 2u);
  EXPECT_EQ(s.meshes[0].indices[1], glm::uvec3(3, 4, 5));
}

TEST_F(GltfLoader, AllIndexComponentTypes) {
  GltfBuilder b;
  const int pos = b.positions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  const int i8 = b.indices<std::uint8_t>({2, 1, 0}, kU8);
  const int i16 = b.indices<std::uint16_t>({1, 2, 0}, kU16);
  const int i32 = b.indices<std::uint32_t>({0, 2, 1}, kU32);
  b.mesh({b.primitive(pos, i8), b.primitive(pos, i16), b.primitive(pos, i32)});
  b.node({{"mesh", 0}});
  const Scene s = load_gltf(write_glb(b));
  ASSERT_EQ(s.meshes[0].indices.size(), 3u);
  EXPECT_EQ(s.meshes[0].indices[0], glm::uvec3(2, 1, 0));
  EXPECT_EQ(s.meshes[0].indices[1], glm::uvec3(4, 5, 3));  // second primitive's vertices start at 3
  EXPECT_EQ(s.meshes[0].indices[2], glm::uvec3(6, 8, 7));
}

TEST_F(GltfLoader, ByteStrideOfInterleavedPositionsIsRespected) {
  GltfBuilder b;
  // position + normal per vertex: stride 24, positions at offset 0.
  std::vector<float> interleaved = {0, 0, 0, 9, 9, 9, 1, 0, 0, 9, 9, 9, 0, 1, 0, 9, 9, 9};
  const int view = b.view(interleaved.data(), interleaved.size() * 4, 24);
  const int pos = b.accessor(view, kFloat, 3, "VEC3");
  b.mesh({b.primitive(pos)});
  b.node({{"mesh", 0}});
  const Scene s = load_gltf(write_gltf(b));
  ASSERT_EQ(s.triangles.size(), 1u);
  expect_vec3_near(s.triangles[0].v1, {1, 0, 0});
  expect_vec3_near(s.triangles[0].v2, {0, 1, 0});
}

TEST_F(GltfLoader, PointsAndLinesAreSkippedWithAWarning) {
  GltfBuilder b;
  const int pos = b.positions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  b.mesh({b.primitive(pos, -1, 0), b.primitive(pos, -1, 1), b.primitive(pos, -1, 3), b.primitive(pos, -1, 4)});
  b.node({{"mesh", 0}});
  const Scene s = load_gltf(write_gltf(b));
  EXPECT_EQ(s.report.skipped_primitives, 3u);
  EXPECT_EQ(s.triangles.size(), 1u);
  std::string all;
  for (const std::string& w : s.report.warnings) all += w + "|";
  EXPECT_NE(all.find("POINTS"), std::string::npos) << all;
  EXPECT_NE(all.find("LINES"), std::string::npos) << all;
  EXPECT_NE(all.find("LINE_STRIP"), std::string::npos) << all;
}

TEST_F(GltfLoader, ManyWarningsAreCapped) {
  GltfBuilder b;
  const int pos = b.positions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  std::vector<json> primitives(150, b.primitive(pos, -1, 0));
  primitives.push_back(b.primitive(pos));
  b.mesh(primitives);
  b.node({{"mesh", 0}});
  const Scene s = load_gltf(write_glb(b));
  EXPECT_EQ(s.report.skipped_primitives, 150u);  // every one counted
  ASSERT_EQ(s.report.warnings.size(), 101u);     // but not every one listed
  EXPECT_EQ(s.report.warnings.back(), "... and 50 more warnings");
}

TEST_F(GltfLoader, PerspectiveCameraConvertedToWorldSpace) {
  GltfBuilder b = one_triangle();
  b.doc["cameras"] = json::array(
      {json{{"type", "perspective"},
            {"name", "main"},
            {"perspective", {{"yfov", 0.5}, {"aspectRatio", 1.5}, {"znear", 0.1}}}},
       json{{"type", "orthographic"}, {"orthographic", {{"xmag", 1}, {"ymag", 1}, {"znear", 0.1}, {"zfar", 10}}}}});
  const glm::quat r = glm::angleAxis(glm::radians(90.0f), glm::vec3(0, 1, 0));
  const int cam = b.node({{"camera", 0}, {"translation", {0, 0, 10}}, {"rotation", {r.x, r.y, r.z, r.w}}});
  const int ortho = b.node({{"camera", 1}});
  b.scene({0, cam, ortho});
  const Scene s = load_gltf(write_gltf(b));
  ASSERT_EQ(s.cameras.size(), 1u);  // the orthographic one is skipped, with a warning
  const Camera& c = s.cameras[0];
  EXPECT_EQ(c.name, "main");
  expect_vec3_near(c.position, {0, 0, 10});
  expect_vec3_near(c.forward, {-1, 0, 0});  // -Z turned 90 degrees about +Y
  expect_vec3_near(c.up, {0, 1, 0});
  EXPECT_FLOAT_EQ(c.yfov, 0.5f);
  EXPECT_FLOAT_EQ(c.aspect, 1.5f);
  EXPECT_EQ(s.nodes[std::size_t(cam)].camera, 0);
  EXPECT_EQ(s.nodes[std::size_t(ortho)].camera, -1);
  EXPECT_TRUE(warned(s, "orthographic"));
}

// A yfov that rounds to float's pi (3.14159265) is a 180-degree view: tan(yfov/2) came out
// negative and the camera was taken. An aspectRatio that is negative or absurd was dropped without
// a word; it is said, and the view's own aspect is used.
TEST_F(GltfLoader, CameraYfovOfPiInFloatAndBadAspectRatiosAreSaid) {
  GltfBuilder b = one_triangle();
  b.doc["cameras"] = json::array(
      {json{{"type", "perspective"}, {"perspective", {{"yfov", 3.14159265}, {"znear", 0.1}}}},
       json{{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"aspectRatio", -2.0}, {"znear", 0.1}}}},
       json{{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"aspectRatio", 1e30}, {"znear", 0.1}}}}});
  const int c0 = b.node({{"camera", 0}, {"translation", {0, 0, 5}}});
  const int c1 = b.node({{"camera", 1}, {"translation", {0, 0, 5}}});
  const int c2 = b.node({{"camera", 2}, {"translation", {0, 0, 5}}});
  b.scene({0, c0, c1, c2});
  const Scene s = load_gltf(write_gltf(b));
  ASSERT_EQ(s.cameras.size(), 2u) << "the 180-degree one is skipped";
  for (const Camera& c : s.cameras) EXPECT_EQ(c.aspect, 0.0f) << "the view's own aspect";
  EXPECT_TRUE(warned(s, "camera 0 (node 1) has an invalid yfov 3.14159"));
  EXPECT_TRUE(warned(s, "camera 1 (node 2) has an invalid aspectRatio -2.000000; the view's own is used"));
  EXPECT_TRUE(warned(s, "camera 2 (node 3) has an invalid aspectRatio"));
}

// A light's colour of 1e39 became inf in float, and `export` then refused the scene it had loaded
// without a word; a negative intensity or range is not a light's. Each is said and a default used.
TEST_F(GltfLoader, LightsWithInvalidColourIntensityOrRangeAreSaid) {
  GltfBuilder b = one_triangle();
  b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  b.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array(
      {json{{"type", "point"}, {"color", {1e39, 0.5, 0.25}}, {"intensity", -5}, {"range", -1}}});
  const int point = b.node({{"translation", {1, 2, 3}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  b.scene({0, point});
  const Scene s = load_gltf(write_gltf(b));
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.lights[0].color, glm::vec3(1.0f));
  EXPECT_EQ(s.lights[0].intensity, 1.0f);
  EXPECT_EQ(s.lights[0].range, 0.0f);
  EXPECT_TRUE(warned(s, "light 0 (node 1) has an invalid color (negative or beyond float); white is used"));
  EXPECT_TRUE(warned(s, "light 0 (node 1) has an invalid intensity -5.000000; 1 is used"));
  EXPECT_TRUE(warned(s, "light 0 (node 1) has an invalid range -1.000000; unlimited is used"));
}

TEST_F(GltfLoader, PunctualLightsConvertedToWorldSpace) {
  GltfBuilder b = one_triangle();
  b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  b.doc["extensionsRequired"] = {"KHR_lights_punctual"};
  b.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array(
      {json{{"type", "point"}, {"color", {1, 0.5, 0.25}}, {"intensity", 20}, {"range", 50}, {"name", "bulb"}},
       json{{"type", "spot"}, {"spot", {{"outerConeAngle", 0.5}}}}, json{{"type", "directional"}, {"intensity", 3}}});
  const glm::quat down = glm::angleAxis(glm::radians(-90.0f), glm::vec3(1, 0, 0));
  const int point = b.node({{"translation", {1, 2, 3}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  const int spot = b.node({{"translation", {0, 5, 0}},
                           {"rotation", {down.x, down.y, down.z, down.w}},
                           {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
  const int sun = b.node({{"extensions", {{"KHR_lights_punctual", {{"light", 2}}}}}});
  b.scene({0, point, spot, sun});
  const Scene s = load_gltf(write_gltf(b));
  ASSERT_EQ(s.lights.size(), 3u);
  EXPECT_EQ(s.lights[0].kind, Light::Kind::point);
  EXPECT_EQ(s.lights[0].name, "bulb");
  expect_vec3_near(s.lights[0].position, {1, 2, 3});
  expect_vec3_near(s.lights[0].color, {1, 0.5f, 0.25f});
  EXPECT_FLOAT_EQ(s.lights[0].intensity, 20.0f);
  EXPECT_FLOAT_EQ(s.lights[0].range, 50.0f);
  EXPECT_EQ(s.lights[1].kind, Light::Kind::spot);
  expect_vec3_near(s.lights[1].position, {0, 5, 0});
  expect_vec3_near(s.lights[1].direction, {0, -1, 0});
  EXPECT_EQ(s.lights[2].kind, Light::Kind::directional);
  expect_vec3_near(s.lights[2].direction, {0, 0, -1});
  EXPECT_FLOAT_EQ(s.lights[2].range, 0.0f);
  EXPECT_EQ(s.nodes[std::size_t(spot)].light, 1);
}

// A NaN or infinite keyframe time or value made every sample of its channel
// NaN, and the two-level structure then failed far from the file: refused
// at load, naming the file, the animation's channel and the keyframe.
TEST_F(GltfLoader, NonFiniteKeyframeTimesAndValuesAreRefused) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const auto with = [&](std::vector<float> times, std::vector<float> values, const std::string& name) {
    GltfBuilder b = one_triangle();
    const int in = b.floats(times, "SCALAR", 1);
    const int out = b.floats(values, "VEC3", 3);
    b.doc["animations"] =
        json::array({json{{"samplers", {{{"input", in}, {"output", out}}}},
                          {"channels", {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "translation"}}}}}}}});
    return write_glb(b, name);
  };
  expect_error(with({0.0f, nan}, {0, 0, 0, 1, 1, 1}, "nan_time.glb"), "keyframe 1 has time nan (times must be finite)");
  expect_error(with({-inf, 1.0f}, {0, 0, 0, 1, 1, 1}, "inf_time.glb"), "keyframe 0 has time -inf");
  expect_error(with({0.0f, 1.0f}, {0, 0, 0, 1, nan, 1}, "nan_value.glb"), "output value 1 (keyframe 1) is not finite");
  expect_error(with({0.0f, 1.0f}, {inf, 0, 0, 1, 1, 1}, "inf_value.glb"), "output value 0 (keyframe 0) is not finite");
  EXPECT_EQ(load_gltf(with({0.0f, 1.0f}, {0, 0, 0, 1, 1, 1}, "fine.glb")).animations.size(), 1u);
}

// What an animated node cannot carry along is said, once per node: a light or a camera on it (or
// below it) stays at its rest pose; a node given by a matrix (glTF forbids animating one) loses the
// matrix to the animated TRS.
// An image that cannot be read is one warning in our words (tinygltf said it in two lines, its own
// "Failed to load external 'uri' for image[0] name = []" the second).
TEST_F(GltfLoader, AnUnreadableImageIsOneWarning) {
  GltfBuilder b = one_triangle();
  b.doc["images"] = json::array({json{{"uri", "nothere.png"}}});
  const Scene missing = load_gltf(write_glb(b, "missing_image.glb"));
  ASSERT_EQ(missing.report.warnings.size(), 1u) << missing.report.warnings.front();
  EXPECT_EQ(missing.report.warnings[0],
            "image 0: 'nothere.png' not found (images are never decoded: no traced triangle changes)");
  fs::create_directories(dir_ / "adir.png");
  b.doc["images"] = json::array({json{{"uri", "adir.png"}}});
  const Scene folder = load_gltf(write_glb(b, "folder_image.glb"));
  ASSERT_EQ(folder.report.warnings.size(), 1u) << folder.report.warnings.front();
  EXPECT_TRUE(warned(folder, "image 0: ")) << folder.report.warnings[0];
  EXPECT_TRUE(warned(folder, "adir.png: is a directory, not a file")) << folder.report.warnings[0];
  EXPECT_EQ(missing.triangles.size(), 1u);
}

TEST_F(GltfLoader, AnimatedNodesSayWhatDoesNotFollow) {
  GltfBuilder b = one_triangle();
  b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  b.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array({json{{"type", "point"}}});
  const int lamp = b.node({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  const int holder = b.node({{"children", {lamp}}});
  const int sheared = b.node({{"mesh", 0}, {"matrix", {1, 0, 0, 0, 0.5, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}});
  b.scene({0, holder, sheared});
  const int times = b.floats({0.0f, 1.0f}, "SCALAR", 1);
  const int moves = b.floats({0, 0, 0, 0, 0, -3}, "VEC3", 3);
  b.doc["animations"] = json::array({json{{"samplers", {{{"input", times}, {"output", moves}}}},
                                          {"channels",
                                           {{{"sampler", 0}, {"target", {{"node", holder}, {"path", "translation"}}}},
                                            {{"sampler", 0}, {"target", {{"node", sheared}, {"path", "translation"}}}},
                                            {{"sampler", 0}, {"target", {{"node", 0}, {"path", "translation"}}}}}}}});
  const Scene s = load_gltf(write_glb(b));
  EXPECT_TRUE(warned(s, "node " + std::to_string(holder) +
                            " is animated and carries light 0: lights and cameras "
                            "stay where the rest pose puts them"));
  EXPECT_TRUE(warned(s, "node " + std::to_string(sheared) + " is animated but given by a matrix (glTF forbids it)"));
  EXPECT_FALSE(warned(s, "node 0 is animated")) << "a plain TRS mesh node moves as it should";
}

// One shape per mesh: a node of a morphing mesh without weights of its own takes another node's,
// not the mesh's defaults; said (it was silent, and its box was another node's shape).
TEST_F(GltfLoader, ANodeWithoutMorphWeightsBesideOneWithThemIsWarned) {
  for (const bool weighted_first : {true, false}) {
    SCOPED_TRACE(weighted_first);
    GltfBuilder b;
    const int pos = b.positions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
    const int lift = b.positions({{0, 0, 0}, {0, 0, 0}, {2, 2, 0}});
    b.doc["meshes"] =
        json::array({json{{"primitives", json::array({json{{"attributes", {{"POSITION", pos}}},
                                                           {"targets", json::array({json{{"POSITION", lift}}})}}})},
                          {"weights", {0.0}}}});
    const json weighted = {{"mesh", 0}, {"weights", {1.0}}}, plain = {{"mesh", 0}, {"translation", {5, 0, 0}}};
    b.node(weighted_first ? weighted : plain);
    b.node(weighted_first ? plain : weighted);
    b.scene({0, 1});
    const Scene s = load_gltf(write_glb(b, weighted_first ? "wf.glb" : "pf.glb"));
    const std::string plain_node = weighted_first ? "node 1" : "node 0";
    EXPECT_TRUE(warned(s, plain_node + " has no morph weights of its own, but another node of mesh 0 has"));
  }
}

TEST_F(GltfLoader, AnimationsAreKeptAsData) {
  GltfBuilder b = one_triangle();
  const int times = b.floats({0.0f, 1.0f}, "SCALAR", 1);
  const int translations = b.floats({0, 0, 0, 1, 2, 3}, "VEC3", 3);
  const int rotations = b.floats({0, 0, 0, 1, 0, 0.70710678f, 0, 0.70710678f}, "VEC4", 4);
  // Cubic spline: in-tangent, value, out-tangent per key.
  const int scales = b.floats({0, 0, 0, 1, 1, 1, 0, 0, 0, 0, 0, 0, 2, 2, 2, 0, 0, 0}, "VEC3", 3);
  b.doc["animations"] = json::array({json{{"name", "wobble"},
                                          {"samplers",
                                           {{{"input", times}, {"output", translations}},
                                            {{"input", times}, {"output", rotations}, {"interpolation", "STEP"}},
                                            {{"input", times}, {"output", scales}, {"interpolation", "CUBICSPLINE"}}}},
                                          {"channels",
                                           {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "translation"}}}},
                                            {{"sampler", 1}, {"target", {{"node", 0}, {"path", "rotation"}}}},
                                            {{"sampler", 2}, {"target", {{"node", 0}, {"path", "scale"}}}}}}}});
  const Scene s = load_gltf(write_glb(b));
  ASSERT_EQ(s.animations.size(), 1u);
  const Animation& a = s.animations[0];
  EXPECT_EQ(a.name, "wobble");
  ASSERT_EQ(a.channels.size(), 3u);

  const AnimationChannel& t = a.channels[0];
  EXPECT_EQ(t.node, 0);
  EXPECT_EQ(t.path, AnimationChannel::Path::translation);
  EXPECT_EQ(t.interpolation, AnimationChannel::Interpolation::linear);
  EXPECT_EQ(t.times, (std::vector<float>{0.0f, 1.0f}));
  ASSERT_EQ(t.values.size(), 2u);
  EXPECT_EQ(t.values[1], glm::vec4(1, 2, 3, 0));  // widened to vec4

  const AnimationChannel& r = a.channels[1];
  EXPECT_EQ(r.path, AnimationChannel::Path::rotation);
  EXPECT_EQ(r.interpolation, AnimationChannel::Interpolation::step);
  ASSERT_EQ(r.values.size(), 2u);
  EXPECT_FLOAT_EQ(r.values[1].y, 0.70710678f);  // stored as glTF's xyzw
  EXPECT_FLOAT_EQ(r.values[1].w, 0.70710678f);

  const AnimationChannel& sc = a.channels[2];
  EXPECT_EQ(sc.interpolation, AnimationChannel::Interpolation::cubic_spline);
  ASSERT_EQ(sc.values.size(), 6u);
  EXPECT_EQ(sc.values[4], glm::vec4(2, 2, 2, 0));
}

TEST_F(GltfLoader, ExternalBufferFileNextToTheGltf) {
  const GltfBuilder b = one_triangle();
  write_file(dir_ / "data.bin", std::string(b.bin.begin(), b.bin.end()));
  EXPECT_EQ(load_gltf(write_gltf_with_buffer_uri("data.bin")).triangles.size(), 1u);
}

TEST_F(GltfLoader, NonFiniteTrianglesAreDroppedAndCounted) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  GltfBuilder b;
  const int pos = b.positions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {nan, 0, 0}, {0, inf, 0}});
  const int idx = b.indices<std::uint16_t>({0, 1, 2, 0, 1, 3, 4, 1, 2}, kU16);
  b.mesh({b.primitive(pos, idx)});
  b.node({{"mesh", 0}});
  const Scene s = load_gltf(write_gltf(b));
  EXPECT_EQ(s.triangles.size(), 1u);
  EXPECT_EQ(s.report.dropped_nonfinite, 2u);
}

TEST_F(GltfLoader, DegenerateTrianglesAreKeptAndCounted) {
  GltfBuilder b;
  const int pos = b.positions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}});
  const int idx = b.indices<std::uint16_t>({0, 1, 2, 0, 1, 3, 2, 2, 2}, kU16);  // collinear; one point
  b.mesh({b.primitive(pos, idx)});
  b.node({{"mesh", 0}});
  const Scene s = load_gltf(write_gltf(b));
  EXPECT_EQ(s.triangles.size(), 3u);
  EXPECT_EQ(s.report.degenerate, 2u);
}

TEST_F(GltfLoader, DeepChainOf100000NodesLoadsWithoutRecursion) {
  constexpr int kDepth = 100000;
  GltfBuilder b;
  const int pos = b.positions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  b.mesh({b.primitive(pos)});
  json nodes = json::array();
  for (int i = 0; i < kDepth; ++i) {
    json n = {{"translation", {1, 0, 0}}};
    if (i + 1 < kDepth)
      n["children"] = {i + 1};
    else
      n["mesh"] = 0;
    nodes.push_back(std::move(n));
  }
  b.doc["nodes"] = std::move(nodes);
  b.scene({0});
  const auto start = std::chrono::steady_clock::now();
  const Scene s = load_gltf(write_glb(b));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(s.triangles.size(), 1u);
  EXPECT_FLOAT_EQ(s.triangles[0].v0.x, float(kDepth));  // every translation applied
  EXPECT_EQ(s.nodes.size(), std::size_t(kDepth));
  EXPECT_EQ(s.nodes[kDepth - 1].parent, kDepth - 2);
  EXPECT_LT(seconds, 20.0);
}

// --- errors: every message names the file and the problem -----------------------

TEST_F(GltfLoader, MissingFile) {
  expect_error(path("absent.gltf"), "no such file");
}

TEST_F(GltfLoader, Directory) {
  fs::create_directories(dir_ / "folder.gltf");
  expect_error(path("folder.gltf"), "is a directory");
}

TEST_F(GltfLoader, TruncatedGlb) {
  const std::string bytes = one_triangle().glb_bytes();
  write_file(dir_ / "cut.glb", bytes.substr(0, bytes.size() / 2));
  expect_error(path("cut.glb"), "truncated GLB");
  write_file(dir_ / "tiny.glb", bytes.substr(0, 7));
  expect_error(path("tiny.glb"), "truncated GLB");
}

// A file over 4 GiB (sparse: no disk is used) is refused with the glTF
// loader's own words for its limit, not the generic size message.
TEST_F(GltfLoader, FileOver4GiBIsRefusedByName) {
  write_file(dir_ / "huge.glb", one_triangle().glb_bytes());
  fs::resize_file(dir_ / "huge.glb", (std::uintmax_t{1} << 32) + 1);
  expect_error(path("huge.glb"), "file is larger than 4 GiB, which glTF loading does not support");
}

TEST_F(GltfLoader, ExternalBufferOver4GiBIsRefusedByName) {
  const GltfBuilder b = one_triangle();
  write_file(dir_ / "huge.bin", std::string(b.bin.begin(), b.bin.end()));
  fs::resize_file(dir_ / "huge.bin", (std::uintmax_t{1} << 32) + 1);
  expect_error(write_gltf_with_buffer_uri("huge.bin"),
               "file is larger than 4 GiB, which glTF loading does not support");
}

// A JSON chunk of length 0 followed by more bytes: those bytes were read as
// the next chunk's header ("chunk 1 length 1935745659 ...").
TEST_F(GltfLoader, EmptyJsonChunkIsNamed) {
  const std::string bytes = one_triangle().glb_bytes();
  std::string glb = bytes;
  const std::uint32_t zero = 0;
  std::memcpy(&glb[12], &zero, 4);
  write_file(dir_ / "empty_json.glb", glb);
  expect_error(path("empty_json.glb"), "malformed GLB: empty JSON chunk");
}

TEST_F(GltfLoader, WrongMagic) {
  std::string bytes = one_triangle().glb_bytes();
  bytes[3] = 'X';
  write_file(dir_ / "magic.glb", bytes);
  expect_error(path("magic.glb"), "wrong magic");
}

TEST_F(GltfLoader, JsonChunkLengthLargerThanFile) {
  std::string bytes = one_triangle().glb_bytes();
  const std::uint32_t huge = 0x7FFFFFF0;
  std::memcpy(&bytes[12], &huge, 4);
  write_file(dir_ / "chunk.glb", bytes);
  expect_error(path("chunk.glb"), "chunk 0 length 2147483632 is larger than");
}

TEST_F(GltfLoader, BinChunkLengthLargerThanFile) {
  // tinygltf alone accepts a BIN length up to 8 bytes past the end.
  std::string bytes = one_triangle().glb_bytes();
  std::uint32_t json_length;
  std::memcpy(&json_length, &bytes[12], 4);
  const std::size_t bin_header = 20 + json_length;
  std::uint32_t bin_length;
  std::memcpy(&bin_length, &bytes[bin_header], 4);
  bin_length += 8;
  std::memcpy(&bytes[bin_header], &bin_length, 4);
  write_file(dir_ / "bin.glb", bytes);
  expect_error(path("bin.glb"), "chunk 1 length");
}

TEST_F(GltfLoader, MalformedJson) {
  std::string text = one_triangle().gltf_text();
  write_file(dir_ / "bad.gltf", text.substr(0, text.size() / 2));
  expect_error(path("bad.gltf"), "malformed JSON");
  // The parser stops at a NUL as at the end: junk after one was accepted. NUL padding is let be.
  write_file(dir_ / "nul.gltf", text + std::string(1, '\0') + "junk");
  expect_error(path("nul.gltf"),
               "malformed JSON: a NUL byte at offset " + std::to_string(text.size()) + " with more after it");
  write_file(dir_ / "padded.gltf", text + std::string(3, '\0'));
  EXPECT_EQ(load_gltf(path("padded.gltf")).triangles.size(), 1u);
  write_file(dir_ / "empty.gltf", "");
  expect_error(path("empty.gltf"), "empty file");
  write_file(dir_ / "array.gltf", "[1, 2, 3]");
  expect_error(path("array.gltf"), "root is not an object");
}

TEST_F(GltfLoader, BufferViewBeyondItsBuffer) {
  GltfBuilder b = one_triangle();
  b.doc["bufferViews"][0]["byteLength"] = 4096;
  expect_error(write_gltf(b), "bufferView 0 spans bytes [0, 0 + 4096) but buffer 0 has");
}

TEST_F(GltfLoader, AccessorBeyondItsBufferView) {
  GltfBuilder b = one_triangle();
  b.doc["accessors"][0]["count"] = 4;
  expect_error(write_gltf(b), "accessor 0 (POSITION of mesh 0 primitive 0): 4 elements of 12 bytes");
  b.doc["accessors"][0]["count"] = 3;
  b.doc["accessors"][0]["byteOffset"] = 4;
  expect_error(write_gltf(b, "offset.gltf"), "do not fit in bufferView 0");
}

TEST_F(GltfLoader, AccessorCountThatWouldOverflow) {
  GltfBuilder b = one_triangle();
  b.doc["accessors"][0]["count"] = std::uint64_t{1} << 62;
  expect_error(write_gltf(b), "do not fit in bufferView 0");
}

TEST_F(GltfLoader, AccessorIndexOutOfRange) {
  GltfBuilder b = one_triangle();
  b.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 9;
  expect_error(write_gltf(b), "refers to accessor 9");
}

TEST_F(GltfLoader, IndexValueOutOfRange) {
  GltfBuilder b;
  const int pos = b.positions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  const int idx = b.indices<std::uint16_t>({0, 1, 7}, kU16);
  b.mesh({b.primitive(pos, idx)});
  b.node({{"mesh", 0}});
  expect_error(write_gltf(b),
               "index 7 at position 2 of accessor 1 is out of range (mesh 0 primitive 0 has 3 vertices)");
}

TEST_F(GltfLoader, NonFloatPositionsRejected) {
  GltfBuilder b;
  const std::vector<std::uint16_t> q = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const int pos = b.accessor(b.view(q.data(), q.size() * 2), kU16, 3, "VEC3");
  b.mesh({b.primitive(pos)});
  b.node({{"mesh", 0}});
  expect_error(write_gltf(b), "UNSIGNED_SHORT (quantized positions, KHR_mesh_quantization, are not supported");
}

TEST_F(GltfLoader, SparseAccessorRejected) {
  GltfBuilder b = one_triangle();
  const std::vector<std::uint16_t> which = {1};
  const std::vector<float> value = {5, 5, 5};
  const int iv = b.view(which.data(), 2);
  const int vv = b.view(value.data(), 12);
  b.doc["accessors"][0]["sparse"] = {
      {"count", 1}, {"indices", {{"bufferView", iv}, {"componentType", kU16}}}, {"values", {{"bufferView", vv}}}};
  expect_error(write_gltf(b), "uses sparse storage, which is not supported");
}

TEST_F(GltfLoader, NodeCycle) {
  GltfBuilder b = one_triangle();
  b.doc.erase("scenes");
  b.doc.erase("scene");
  b.doc["nodes"] =
      json::array({json{{"mesh", 0}, {"children", {1}}}, json{{"children", {2}}}, json{{"children", {0}}}});
  expect_error(write_gltf(b), "node cycle: 0 -> 1 -> 2 -> 0");
}

TEST_F(GltfLoader, SelfParentedNode) {
  GltfBuilder b = one_triangle();
  b.doc["nodes"][0]["children"] = {0};
  expect_error(write_gltf(b), "node 0 is its own child");
}

TEST_F(GltfLoader, NodeWithTwoParents) {
  GltfBuilder b = one_triangle();
  b.node({{"children", {0}}});
  b.node({{"children", {0}}});
  expect_error(write_gltf(b), "node 0 has more than one parent (nodes 1 and 2)");
}

TEST_F(GltfLoader, ChildIndexOutOfRange) {
  GltfBuilder b = one_triangle();
  b.doc["nodes"][0]["children"] = {5};
  expect_error(write_gltf(b), "node 0 has child 5, but the file has 1 nodes");
}

TEST_F(GltfLoader, SceneRootThatIsAChild) {
  GltfBuilder b = one_triangle();
  b.node({{"children", {0}}});
  b.scene({0});
  expect_error(write_gltf(b), "scene 0 lists node 0 as a root, but it is a child of node 1");
}

TEST_F(GltfLoader, NodeReferencingMissingMesh) {
  GltfBuilder b = one_triangle();
  b.doc["nodes"][0]["mesh"] = 3;
  expect_error(write_gltf(b), "node 0 refers to mesh 3, but the file has 1 meshes");
}

TEST_F(GltfLoader, MalformedTranslation) {
  GltfBuilder b = one_triangle();
  b.doc["nodes"][0]["translation"] = {1, 2};
  expect_error(write_gltf(b), "node 0 has a translation of 2 numbers (expected 3)");
}

TEST_F(GltfLoader, UnsupportedRequiredExtensionDraco) {
  GltfBuilder b = one_triangle();
  b.doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
  b.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
  // As a Draco file has it: the accessors carry no bufferView.
  b.doc["accessors"][1].erase("bufferView");
  b.doc["meshes"][0]["primitives"][0]["extensions"] = {
      {"KHR_draco_mesh_compression", {{"bufferView", 0}, {"attributes", {{"POSITION", 0}}}}}};
  expect_error(write_gltf(b), "requires extension 'KHR_draco_mesh_compression', which is not supported");
  expect_error(write_glb(b), "requires extension 'KHR_draco_mesh_compression'");
}

TEST_F(GltfLoader, UnsupportedRequiredExtensionMeshopt) {
  GltfBuilder b = one_triangle();
  b.doc["extensionsRequired"] = {"KHR_lights_punctual", "EXT_meshopt_compression"};
  expect_error(write_gltf(b), "requires extension 'EXT_meshopt_compression'");
}

// A malformed escape in a buffer's URI decodes to a NUL: the message named a
// folder ("File read error : g/") and stopped there.
TEST_F(GltfLoader, ExternalBufferUriWithANulIsNamed) {
  expect_error(write_gltf_with_buffer_uri("%ZZ.bin", "pct.gltf"),
               "?.bin : its name holds a NUL byte (a %00 or malformed escape in the URI)");
}

TEST_F(GltfLoader, MissingExternalBufferFile) {
  expect_error(write_gltf_with_buffer_uri("geometry_missing.bin"),
               "external buffer file 'geometry_missing.bin' not found");
}

TEST_F(GltfLoader, EmptySceneIsAnError) {
  GltfBuilder b;
  b.node({{"name", "lonely"}});
  b.scene({0});
  expect_error(write_gltf(b), "scene contains no triangles");

  GltfBuilder points;  // only a POINTS primitive: still nothing to trace
  const int pos = points.positions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  points.mesh({points.primitive(pos, -1, 0)});
  points.node({{"mesh", 0}});
  expect_error(write_gltf(points, "points.gltf"), "scene contains no triangles (1 point/line primitive skipped)");
}

TEST_F(GltfLoader, DeeplyNestedJsonIsRejectedNotCrashing) {
  std::string text = "{\"asset\":{\"version\":\"2.0\"},\"extras\":";
  for (int i = 0; i < 100000; ++i) text += '[';
  for (int i = 0; i < 100000; ++i) text += ']';
  text += "}";
  write_file(dir_ / "nested.gltf", text);
  expect_error(path("nested.gltf"), "nested deeper than");
}

// --- load_scene: dispatch by extension ------------------------------------------

TEST_F(GltfLoader, LoadSceneDispatchesByExtensionCaseInsensitively) {
  EXPECT_EQ(load_scene(write_gltf(one_triangle(), "upper.GLTF")).triangles.size(), 1u);
  EXPECT_EQ(load_scene(write_glb(one_triangle(), "upper.GlB")).triangles.size(), 1u);
  write_file(dir_ / "tri.OBJ", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const Scene obj = load_scene(path("tri.OBJ"));
  EXPECT_EQ(obj.triangles.size(), 1u);
  EXPECT_EQ(obj.source, path("tri.OBJ"));
}

TEST_F(GltfLoader, LoadSceneRejectsUnknownExtensionsAndMissingFiles) {
  auto message = [](const std::string& spec) {
    try {
      load_scene(spec);
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string("<no error>");
  };
  write_file(dir_ / "mesh.xyz", "solid");
  EXPECT_EQ(message(path("mesh.xyz")),
            path("mesh.xyz") + ": unsupported file type '.xyz' (expected .gltf, .glb or .obj)");
  write_file(dir_ / "noext", "solid");
  EXPECT_EQ(message(path("noext")),
            path("noext") + ": unsupported file type (no extension) (expected .gltf, .glb or .obj)");
  EXPECT_EQ(message(path("absent.glb")), path("absent.glb") + ": no such file");
}

// --- shared asset (optional) ---------------------------------------------------

TEST(GltfLoaderAssets, StanfordBunny) {
  const std::string file = std::string(ACCELVIZ_SHARED_ASSETS) + "/bunny.glb";
  if (!fs::exists(file)) GTEST_SKIP() << file << " not present";
  const Scene s = load_gltf(file);
  EXPECT_EQ(s.triangles.size(), 69451u);
  EXPECT_EQ(s.meshes.at(0).positions.size(), 35947u);
  const Aabb box = s.bounds();
  // Bounds from shared/assets/README.md (printed to 6 significant digits).
  expect_vec3_near(box.lo, {-0.0946899f, 0.0329874f, -0.0618736f}, 1e-6f);
  expect_vec3_near(box.hi, {0.0610091f, 0.187321f, 0.0587997f}, 1e-6f);
  EXPECT_EQ(s.report.dropped_nonfinite, 0u);
}

}  // namespace
}  // namespace unity_test_gltf_loader
