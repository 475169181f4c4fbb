// glTF 2.0 writer. The JSON and the GLB container are written directly with
// nlohmann::json: the format is small, and writing it ourselves keeps the
// output byte-for-byte predictable (chunk padding, one buffer, no defaults
// serialised) and lets us validate the Scene as we go.
#include "core/scene/gltf_writer.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/util/file_checks.h"
#include "core/util/json_text.h"
#include "core/util/output_file.h"

namespace accelviz {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr int kArrayBuffer = 34962;         // bufferView target for vertex data
constexpr int kElementArrayBuffer = 34963;  // bufferView target for indices
constexpr int kFloat = 5126;
constexpr int kUnsignedInt = 5125;

class GltfWriter {
 public:
  GltfWriter(const Scene& scene, const std::string& path) : scene_(scene), path_(path) {}

  json build() {
    json doc;
    doc["asset"] = {{"version", "2.0"}, {"generator", "accelviz"}};
    write_meshes(doc);
    write_nodes(doc);
    write_cameras(doc);
    write_lights(doc);
    if (!nodes_.empty()) {
      doc["nodes"] = std::move(nodes_);
      doc["scenes"] = json::array({json{{"nodes", roots_}}});
      doc["scene"] = 0;
    }
    if (!bin_.empty()) {
      doc["bufferViews"] = std::move(buffer_views_);
      doc["accessors"] = std::move(accessors_);
    }
    return doc;
  }

  std::vector<unsigned char>& bin() { return bin_; }

 private:
  [[noreturn]] void fail(const std::string& problem) const { throw SceneError(path_ + ": " + problem); }

  // --- buffer --------------------------------------------------------------

  /// Appends raw bytes as a new bufferView (4-byte aligned, as accessors of
  /// 4-byte components require) and returns its index.
  int add_view(const void* data, std::size_t bytes, int target) {
    while (bin_.size() % 4 != 0) bin_.push_back(0);
    const std::size_t offset = bin_.size();
    bin_.resize(offset + bytes);
    std::memcpy(bin_.data() + offset, data, bytes);
    buffer_views_.push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}, {"target", target}});
    return int(buffer_views_.size() - 1);
  }

  void write_meshes(json& doc) {
    json meshes = json::array();
    mesh_map_.assign(scene_.meshes.size(), -1);
    for (std::size_t m = 0; m < scene_.meshes.size(); ++m) {
      const Mesh& mesh = scene_.meshes[m];
      // glTF accessors must have count >= 1: an empty mesh cannot be written.
      if (mesh.positions.empty() || mesh.indices.empty()) continue;
      for (const glm::uvec3& t : mesh.indices)
        if (t.x >= mesh.positions.size() || t.y >= mesh.positions.size() || t.z >= mesh.positions.size())
          fail("mesh " + std::to_string(m) + " has an index out of range");

      // min/max are required for POSITION; NaN/inf cannot appear in JSON, so
      // they bound the finite coordinates only.
      glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
      bool any_finite = false;
      for (const glm::vec3& p : mesh.positions) {
        if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))) continue;
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
        any_finite = true;
      }
      if (!any_finite) lo = hi = glm::vec3(0.0f);
      const int pos_view = add_view(mesh.positions.data(), mesh.positions.size() * sizeof(glm::vec3), kArrayBuffer);
      accessors_.push_back({{"bufferView", pos_view},
                            {"componentType", kFloat},
                            {"count", mesh.positions.size()},
                            {"type", "VEC3"},
                            {"min", {lo.x, lo.y, lo.z}},
                            {"max", {hi.x, hi.y, hi.z}}});
      const int pos_accessor = int(accessors_.size() - 1);

      std::uint32_t imin = std::numeric_limits<std::uint32_t>::max(), imax = 0;
      for (const glm::uvec3& t : mesh.indices)
        for (int k = 0; k < 3; ++k) {
          imin = std::min(imin, t[k]);
          imax = std::max(imax, t[k]);
        }
      const int idx_view = add_view(mesh.indices.data(), mesh.indices.size() * sizeof(glm::uvec3), kElementArrayBuffer);
      accessors_.push_back({{"bufferView", idx_view},
                            {"componentType", kUnsignedInt},
                            {"count", mesh.indices.size() * 3},
                            {"type", "SCALAR"},
                            {"min", {imin}},
                            {"max", {imax}}});
      const int idx_accessor = int(accessors_.size() - 1);

      json jm = {{"primitives", json::array({json{{"attributes", {{"POSITION", pos_accessor}}},
                                                  {"indices", idx_accessor},
                                                  {"mode", 4}}})}};
      if (!mesh.name.empty()) jm["name"] = mesh.name;
      meshes.push_back(std::move(jm));
      mesh_map_[m] = int(meshes.size() - 1);
    }
    if (!meshes.empty()) doc["meshes"] = std::move(meshes);
  }

  // --- nodes ---------------------------------------------------------------

  static bool close(const glm::mat4& a, const glm::mat4& b) {
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        if (!(std::fabs(a[c][r] - b[c][r]) <= 1e-5f * std::max(1.0f, std::fabs(b[c][r])))) return false;
    return true;
  }

  static json matrix_json(const glm::mat4& m) {
    json out = json::array();
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) out.push_back(m[c][r]);
    return out;
  }

  static bool finite(const glm::mat4& m) {
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        if (!std::isfinite(m[c][r])) return false;
    return true;
  }

  /// The node's local transform as glTF properties: TRS when it reproduces
  /// `local` (the authoritative one), else the matrix.
  static void put_transform(json& jn, const Node& node) {
    const glm::mat4 trs = glm::translate(glm::mat4(1.0f), node.translation) * glm::mat4_cast(node.rotation) *
                          glm::scale(glm::mat4(1.0f), node.scale);
    if (node.has_matrix || !close(trs, node.local)) {
      if (node.local != glm::mat4(1.0f)) jn["matrix"] = matrix_json(node.local);
      return;
    }
    if (node.translation != glm::vec3(0.0f))
      jn["translation"] = {node.translation.x, node.translation.y, node.translation.z};
    if (node.rotation != glm::quat(1.0f, 0.0f, 0.0f, 0.0f))
      jn["rotation"] = {node.rotation.x, node.rotation.y, node.rotation.z, node.rotation.w};  // glTF order xyzw
    if (node.scale != glm::vec3(1.0f)) jn["scale"] = {node.scale.x, node.scale.y, node.scale.z};
  }

  void write_nodes(json&) {
    const std::size_t n = scene_.nodes.size();
    // Parents from the children lists, which are what the file will hold.
    std::vector<int> parent(n, -1);
    for (std::size_t i = 0; i < n; ++i)
      for (const int c : scene_.nodes[i].children) {
        if (c < 0 || std::size_t(c) >= n || std::size_t(c) == i)
          fail("node " + std::to_string(i) + " has invalid child " + std::to_string(c));
        if (parent[std::size_t(c)] >= 0) fail("node " + std::to_string(c) + " has more than one parent");
        parent[std::size_t(c)] = int(i);
      }
    // With one parent each, a node that no parentless node reaches lies on a
    // cycle; the loader would reject the file, so refuse to write it.
    {
      std::vector<bool> seen(n, false);
      std::vector<std::size_t> todo;
      for (std::size_t i = 0; i < n; ++i)
        if (parent[i] < 0) todo.push_back(i);
      while (!todo.empty()) {
        const std::size_t i = todo.back();
        todo.pop_back();
        seen[i] = true;
        for (const int c : scene_.nodes[i].children) todo.push_back(std::size_t(c));
      }
      for (std::size_t i = 0; i < n; ++i)
        if (!seen[i]) fail("node graph has a cycle through node " + std::to_string(i));
    }
    std::vector<int> roots;
    if (!scene_.roots.empty()) {
      std::vector<bool> listed(n, false);
      for (const int r : scene_.roots) {
        if (r < 0 || std::size_t(r) >= n) fail("root " + std::to_string(r) + " is not a node");
        if (parent[std::size_t(r)] >= 0) fail("root " + std::to_string(r) + " has a parent");
        if (listed[std::size_t(r)]) fail("root " + std::to_string(r) + " is listed twice");
        listed[std::size_t(r)] = true;
        roots.push_back(r);
      }
    } else {
      for (std::size_t i = 0; i < n; ++i)
        if (parent[i] < 0) roots.push_back(int(i));
    }

    // World transforms of the nodes in the written scene, iteratively (deep
    // chains must not recurse); a node seen twice means a cycle.
    std::vector<glm::mat4> world(n, glm::mat4(1.0f));
    std::vector<bool> reached(n, false);
    std::vector<std::size_t> stack;
    for (const int r : roots) {
      world[std::size_t(r)] = scene_.nodes[std::size_t(r)].local;
      stack.push_back(std::size_t(r));
    }
    while (!stack.empty()) {
      const std::size_t i = stack.back();
      stack.pop_back();
      reached[i] = true;
      for (const int c : scene_.nodes[i].children) {
        world[std::size_t(c)] = world[i] * scene_.nodes[std::size_t(c)].local;
        stack.push_back(std::size_t(c));
      }
    }

    // An instance is carried by its own node when that node is in the scene,
    // references the same mesh and sits where the instance says; otherwise
    // it gets a new root node holding its world matrix.
    std::vector<int> node_mesh(n, -1);
    std::vector<const Instance*> extra;
    for (const Instance& inst : scene_.instances) {
      if (inst.mesh >= scene_.meshes.size()) fail("instance refers to missing mesh " + std::to_string(inst.mesh));
      const int written_mesh = mesh_map_[inst.mesh];
      if (written_mesh < 0) continue;  // empty mesh: nothing to place
      if (!finite(inst.transform)) fail("instance of mesh " + std::to_string(inst.mesh) + " has a non-finite transform");
      const std::size_t i = inst.node;
      if (i < n && reached[i] && node_mesh[i] < 0 && scene_.nodes[i].mesh == int(inst.mesh) &&
          close(world[i], inst.transform)) {
        node_mesh[i] = written_mesh;
      } else {
        extra.push_back(&inst);
      }
    }

    for (std::size_t i = 0; i < n; ++i) {
      const Node& node = scene_.nodes[i];
      if (!finite(node.local)) fail("node " + std::to_string(i) + " has a non-finite transform");
      json jn = json::object();
      if (!node.name.empty()) jn["name"] = node.name;
      put_transform(jn, node);
      if (!node.children.empty()) jn["children"] = node.children;
      if (node_mesh[i] >= 0) jn["mesh"] = node_mesh[i];
      nodes_.push_back(std::move(jn));
    }
    roots_ = roots;
    for (const Instance* inst : extra) {
      json jn = {{"mesh", mesh_map_[inst->mesh]}};
      if (inst->transform != glm::mat4(1.0f)) jn["matrix"] = matrix_json(inst->transform);
      add_root(std::move(jn));
    }
  }

  void add_root(json node) {
    roots_.push_back(int(nodes_.size()));
    nodes_.push_back(std::move(node));
  }

  /// A node matrix whose -Z axis is `forward` and +Y is `up` (the glTF
  /// convention for cameras and lights), placed at `position`.
  static glm::mat4 frame(const glm::vec3& position, const glm::vec3& forward, const glm::vec3& up_hint) {
    const glm::vec3 back = -glm::normalize(forward);
    glm::vec3 hint = up_hint;
    if (glm::length(glm::cross(hint, back)) < 1e-6f) hint = std::fabs(back.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    const glm::vec3 right = glm::normalize(glm::cross(hint, back));
    const glm::vec3 up = glm::cross(back, right);
    glm::mat4 m(1.0f);
    m[0] = glm::vec4(right, 0.0f);
    m[1] = glm::vec4(up, 0.0f);
    m[2] = glm::vec4(back, 0.0f);
    m[3] = glm::vec4(position, 1.0f);
    return m;
  }

  static bool finite3(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

  void write_cameras(json& doc) {
    json cameras = json::array();
    for (std::size_t k = 0; k < scene_.cameras.size(); ++k) {
      const Camera& cam = scene_.cameras[k];
      if (!finite3(cam.position) || !finite3(cam.forward) || !finite3(cam.up) || glm::length(cam.forward) == 0.0f)
        fail("camera " + std::to_string(k) + " has a non-finite or zero direction");
      if (!(cam.yfov > 0.0f && std::isfinite(cam.yfov))) fail("camera " + std::to_string(k) + " has an invalid yfov");
      json perspective = {{"yfov", cam.yfov}, {"znear", 0.01}};
      if (cam.aspect > 0.0f) perspective["aspectRatio"] = cam.aspect;
      json jc = {{"type", "perspective"}, {"perspective", perspective}};
      if (!cam.name.empty()) jc["name"] = cam.name;
      cameras.push_back(std::move(jc));
      json jn = {{"camera", int(k)}, {"matrix", matrix_json(frame(cam.position, cam.forward, cam.up))}};
      if (!cam.name.empty()) jn["name"] = cam.name;
      add_root(std::move(jn));
    }
    if (!cameras.empty()) doc["cameras"] = std::move(cameras);
  }

  void write_lights(json& doc) {
    json lights = json::array();
    for (std::size_t k = 0; k < scene_.lights.size(); ++k) {
      const Light& light = scene_.lights[k];
      if (!finite3(light.position) || !finite3(light.direction) || !finite3(light.color) ||
          !std::isfinite(light.intensity) || !std::isfinite(light.range))
        fail("light " + std::to_string(k) + " has non-finite values");
      json jl = {{"color", {light.color.x, light.color.y, light.color.z}}, {"intensity", light.intensity}};
      switch (light.kind) {
        case Light::Kind::point: jl["type"] = "point"; break;
        case Light::Kind::directional: jl["type"] = "directional"; break;
        case Light::Kind::spot:
          jl["type"] = "spot";
          // Written as doubles no wider than glTF's pi/2 (the float pi/2 lies a hair above it).
          jl["spot"] = {{"innerConeAngle", std::min(double(light.inner_cone), 1.5707963267948966)},
                        {"outerConeAngle", std::min(double(light.outer_cone), 1.5707963267948966)}};
          break;
      }
      if (light.range > 0.0f) jl["range"] = light.range;
      if (!light.name.empty()) jl["name"] = light.name;
      lights.push_back(std::move(jl));
      const glm::vec3 dir = glm::length(light.direction) > 0.0f ? light.direction : glm::vec3(0, -1, 0);
      json jn = {{"extensions", {{"KHR_lights_punctual", {{"light", int(k)}}}}},
                 {"matrix", matrix_json(frame(light.position, dir, glm::vec3(0, 1, 0)))}};
      if (!light.name.empty()) jn["name"] = light.name;
      add_root(std::move(jn));
    }
    if (!lights.empty()) {
      doc["extensions"]["KHR_lights_punctual"]["lights"] = std::move(lights);
      doc["extensionsUsed"] = json::array({"KHR_lights_punctual"});
    }
  }

  const Scene& scene_;
  const std::string& path_;
  std::vector<unsigned char> bin_;
  json buffer_views_ = json::array();
  json accessors_ = json::array();
  json nodes_ = json::array();
  std::vector<int> roots_;
  std::vector<int> mesh_map_;  ///< Scene mesh -> written mesh, -1 if left out
};

std::string base64(const std::vector<unsigned char>& data) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((data.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < data.size(); i += 3) {
    const std::uint32_t v = std::uint32_t(data[i]) << 16 | std::uint32_t(data[i + 1]) << 8 | data[i + 2];
    out += table[v >> 18];
    out += table[(v >> 12) & 63];
    out += table[(v >> 6) & 63];
    out += table[v & 63];
  }
  if (i < data.size()) {
    const bool two = i + 1 < data.size();
    const std::uint32_t v = std::uint32_t(data[i]) << 16 | (two ? std::uint32_t(data[i + 1]) << 8 : 0);
    out += table[v >> 18];
    out += table[(v >> 12) & 63];
    out += two ? table[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

void put_u32(std::string& out, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) out += char((v >> (8 * k)) & 0xFF);
}

/// GLB container (glTF 2.0 §4.4): header, JSON chunk padded with spaces, BIN
/// chunk padded with zeros, every chunk 4-byte aligned.
std::string glb_bytes(const std::string& path, std::string json_text, const std::vector<unsigned char>& bin) {
  while (json_text.size() % 4 != 0) json_text += ' ';
  const std::size_t bin_padded = (bin.size() + 3) / 4 * 4;
  const std::uint64_t total = 12 + 8 + std::uint64_t(json_text.size()) + (bin.empty() ? 0 : 8 + bin_padded);
  if (total > std::numeric_limits<std::uint32_t>::max()) throw SceneError(path + ": scene too large for GLB (4 GiB limit)");
  std::string out;
  out.reserve(std::size_t(total));
  put_u32(out, 0x46546C67);  // "glTF"
  put_u32(out, 2);
  put_u32(out, std::uint32_t(total));
  put_u32(out, std::uint32_t(json_text.size()));
  put_u32(out, 0x4E4F534A);  // "JSON"
  out += json_text;
  if (!bin.empty()) {
    put_u32(out, std::uint32_t(bin_padded));
    put_u32(out, 0x004E4942);  // "BIN\0"
    out.append(reinterpret_cast<const char*>(bin.data()), bin.size());
    out.append(bin_padded - bin.size(), '\0');
  }
  return out;
}

}  // namespace

void write_gltf(const Scene& scene, const std::string& path, bool binary, bool overwrite) {
  if (!overwrite && name_taken(path)) throw SceneError(path + ": exists (use --force to overwrite)");
  if (const std::string problem = output_path_problem(path); !problem.empty()) throw SceneError(path + ": " + problem);

  GltfWriter writer(scene, path);
  json doc = writer.build();
  std::vector<unsigned char>& bin = writer.bin();
  std::string bytes;
  if (binary) {
    if (!bin.empty()) doc["buffers"] = json::array({json{{"byteLength", bin.size()}}});
    bytes = glb_bytes(path, json_text(doc), bin);
  } else {
    if (!bin.empty())
      doc["buffers"] = json::array(
          {json{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}});
    bytes = json_text(doc, 1) + "\n";
  }

  // A fresh temporary beside the target, then its name (write_output_file):
  // a failure never leaves a partial file under the real name, and never
  // writes through a link or FIFO that happens to be there.
  const OutputWrite w = write_output_file(path, {bytes}, overwrite);
  if (w.exists) throw SceneError(path + ": exists (use --force to overwrite)");
  if (!w.ok()) throw SceneError(path + ": " + w.problem);
}

}  // namespace accelviz
