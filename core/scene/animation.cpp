// Animation sampling and the per-frame update of a two-level structure (see animation.h).
#include "core/scene/animation.h"
#include "core/util/timing.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

namespace accelviz {

namespace {

using Clock = std::chrono::steady_clock;

glm::quat to_quat(const glm::vec4& v) {
  return glm::quat(v.w, v.x, v.y, v.z);
}
glm::vec4 from_quat(const glm::quat& q) {
  return glm::vec4(q.x, q.y, q.z, q.w);
}

}  // namespace

glm::mat4 compose_trs(const glm::vec3& t, const glm::quat& r, const glm::vec3& s) {
  glm::mat4 m = glm::mat4_cast(r);
  m[0] *= s.x;
  m[1] *= s.y;
  m[2] *= s.z;
  m[3] = glm::vec4(t, 1.0f);
  return m;
}

glm::vec4 sample_channel(const AnimationChannel& c, float t) {
  using I = AnimationChannel::Interpolation;
  const std::size_t keys = c.times.size();
  const std::size_t per_key = c.interpolation == I::cubic_spline ? 3 : 1;
  if (keys == 0) throw std::invalid_argument("animation channel without keys");
  if (c.values.size() != keys * per_key)
    throw std::invalid_argument("animation channel: " + std::to_string(c.values.size()) + " values for " +
                                std::to_string(keys) + " keys (expected " + std::to_string(keys * per_key) + ")");
  const bool rotation = c.path == AnimationChannel::Path::rotation;
  const auto value = [&](std::size_t k) { return c.values[k * per_key + (per_key == 3 ? 1 : 0)]; };
  if (keys == 1 || t <= c.times.front()) return value(0);
  if (t >= c.times.back()) return value(keys - 1);
  // Key interval [k, k+1] holding t.
  const std::size_t k =
      static_cast<std::size_t>(std::upper_bound(c.times.begin(), c.times.end(), t) - c.times.begin()) - 1;
  const float t0 = c.times[k], t1 = c.times[k + 1];
  const float td = t1 - t0;
  const float s = td > 0.0f ? (t - t0) / td : 0.0f;
  switch (c.interpolation) {
    case I::step:
      return value(k);
    case I::linear:
      if (rotation) return from_quat(glm::slerp(to_quat(value(k)), to_quat(value(k + 1)), s));
      return value(k) + s * (value(k + 1) - value(k));
    case I::cubic_spline: {
      // glTF 2.0 Appendix C: Hermite with tangents scaled by the key interval.
      const glm::vec4 p0 = value(k), p1 = value(k + 1);
      const glm::vec4 b0 = c.values[k * 3 + 2];    // out-tangent of k
      const glm::vec4 a1 = c.values[(k + 1) * 3];  // in-tangent of k+1
      const float s2 = s * s, s3 = s2 * s;
      glm::vec4 v =
          (2 * s3 - 3 * s2 + 1) * p0 + td * (s3 - 2 * s2 + s) * b0 + (-2 * s3 + 3 * s2) * p1 + td * (s3 - s2) * a1;
      if (rotation) {
        const float len = glm::length(v);
        if (len > 0.0f) v /= len;
      }
      return v;
    }
  }
  return value(k);
}

std::vector<float> sample_weights(const AnimationChannel& c, float t) {
  using I = AnimationChannel::Interpolation;
  const std::size_t keys = c.times.size();
  const std::size_t per_key = c.interpolation == I::cubic_spline ? 3 : 1;
  if (keys == 0) throw std::invalid_argument("animation channel without keys");
  if (c.values.empty() || c.values.size() % (keys * per_key) != 0)
    throw std::invalid_argument("weights channel: " + std::to_string(c.values.size()) + " values for " +
                                std::to_string(keys) + " keys (expected a positive multiple of " +
                                std::to_string(keys * per_key) + ")");
  const std::size_t n = c.values.size() / (keys * per_key);  // morph targets
  // Key k's block: [in-tangents n][values n][out-tangents n] for cubic spline, [values n] otherwise.
  const auto at = [&](std::size_t k, std::size_t part, std::size_t j) {
    return c.values[(k * per_key + part) * n + j].x;
  };
  const std::size_t vpart = per_key == 3 ? 1 : 0;
  std::vector<float> out(n);
  if (keys == 1 || t <= c.times.front() || t >= c.times.back()) {
    const std::size_t k = keys == 1 || t <= c.times.front() ? 0 : keys - 1;
    for (std::size_t j = 0; j < n; ++j) out[j] = at(k, vpart, j);
    return out;
  }
  const std::size_t k =
      static_cast<std::size_t>(std::upper_bound(c.times.begin(), c.times.end(), t) - c.times.begin()) - 1;
  const float t0 = c.times[k], t1 = c.times[k + 1];
  const float td = t1 - t0;
  const float s = td > 0.0f ? (t - t0) / td : 0.0f;
  for (std::size_t j = 0; j < n; ++j) {
    switch (c.interpolation) {
      case I::step:
        out[j] = at(k, vpart, j);
        break;
      case I::linear:
        out[j] = at(k, 0, j) + s * (at(k + 1, 0, j) - at(k, 0, j));
        break;
      case I::cubic_spline: {
        // glTF 2.0 Appendix C, per weight, as for TRS.
        const float p0 = at(k, 1, j), p1 = at(k + 1, 1, j);
        const float b0 = at(k, 2, j), a1 = at(k + 1, 0, j);
        const float s2 = s * s, s3 = s2 * s;
        out[j] =
            (2 * s3 - 3 * s2 + 1) * p0 + td * (s3 - 2 * s2 + s) * b0 + (-2 * s3 + 3 * s2) * p1 + td * (s3 - s2) * a1;
        break;
      }
    }
  }
  return out;
}

namespace {

/// The first weights channel whose node references MESH (null: none).
const AnimationChannel* weights_channel_of(const Scene& scene, std::uint32_t mesh) {
  for (const Animation& a : scene.animations)
    for (const AnimationChannel& c : a.channels)
      if (c.path == AnimationChannel::Path::weights && !c.times.empty() && c.node >= 0 &&
          static_cast<std::size_t>(c.node) < scene.nodes.size() && scene.nodes[c.node].mesh == static_cast<int>(mesh))
        return &c;
  return nullptr;
}

/// Positions moved by deformer D at time T (the grass sway; see MeshDeformer).
std::vector<glm::vec3> sway(std::span<const glm::vec3> positions, const MeshDeformer& d, float t) {
  const float w0 = 2.0f * 3.14159265358979f * d.frequency * t;
  std::vector<glm::vec3> moved(positions.size());
  for (std::size_t i = 0; i < moved.size(); ++i) {
    const glm::vec3& p = positions[i];
    const float h = d.height > 0.0f ? std::max(0.0f, p.y) / d.height : 0.0f;
    const float amp = d.amplitude * h * h;
    const float w = w0 + 0.7f * p.x + 0.5f * p.z;
    moved[i] = p + glm::vec3(amp * std::sin(w), 0.0f, 0.5f * amp * std::cos(w));
  }
  return moved;
}

/// MESH's triangles over MOVED vertices, skipping those whose rest vertices
/// are not finite (as the BLAS was built).
std::vector<Triangle> triangles_over(const Mesh& mesh, const std::vector<glm::vec3>& moved) {
  const auto finite3 = [](const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
  };
  std::vector<Triangle> out;
  out.reserve(mesh.indices.size());
  for (const glm::uvec3& idx : mesh.indices) {
    const glm::vec3 &a = mesh.positions[idx.x], &b = mesh.positions[idx.y], &c = mesh.positions[idx.z];
    if (!finite3(a) || !finite3(b) || !finite3(c)) continue;
    out.push_back({moved[idx.x], moved[idx.y], moved[idx.z]});
  }
  return out;
}

}  // namespace

std::vector<char> nodes_placing_instances(const Scene& scene) {
  std::vector<char> placing(scene.nodes.size(), 0);
  for (const Instance& inst : scene.instances)
    for (int n = static_cast<int>(inst.node); n >= 0 && static_cast<std::size_t>(n) < scene.nodes.size() && !placing[n];
         n = scene.nodes[n].parent)
      placing[n] = 1;
  return placing;
}

namespace {

/// Key k's entries of a channel: [in-tangents n][values n][out-tangents n] for a cubic spline,
/// [values n] otherwise (n: 1 for translation, rotation and scale; the target count for weights).
/// True when every key holds `rest` (n values) and no tangent bends between keys.
bool channel_holds(const AnimationChannel& c, std::span<const glm::vec4> rest) {
  const std::size_t keys = c.times.size();
  const std::size_t per_key = c.interpolation == AnimationChannel::Interpolation::cubic_spline ? 3 : 1;
  if (keys == 0 || c.values.size() != keys * per_key * rest.size()) return false;  // malformed: assume it moves
  const std::size_t n = rest.size(), vpart = per_key == 3 ? 1 : 0;
  for (std::size_t k = 0; k < keys; ++k)
    for (std::size_t part = 0; part < per_key; ++part)
      for (std::size_t j = 0; j < n; ++j) {
        const glm::vec4& v = c.values[(k * per_key + part) * n + j];
        if (part == vpart ? v != rest[j] : v != glm::vec4(0.0f)) return false;
      }
  return true;
}

/// A channel's first value, the rest its keys would have to hold for it to never change anything.
std::vector<glm::vec4> first_values(const AnimationChannel& c, std::size_t n) {
  const std::size_t vpart = c.interpolation == AnimationChannel::Interpolation::cubic_spline ? 1 : 0;
  std::vector<glm::vec4> v(n, glm::vec4(0.0f));
  for (std::size_t j = 0; j < n && vpart * n + j < c.values.size(); ++j) v[j] = c.values[vpart * n + j];
  return v;
}

}  // namespace

bool channel_moves(const Scene& scene, const AnimationChannel& c, const std::vector<char>& placing) {
  if (c.node < 0 || static_cast<std::size_t>(c.node) >= scene.nodes.size() || c.times.empty()) return false;
  if (!placing[static_cast<std::size_t>(c.node)]) return false;  // no instance below it: nothing to move
  const Node& node = scene.nodes[static_cast<std::size_t>(c.node)];
  using P = AnimationChannel::Path;
  if (c.path == P::weights) {
    if (node.mesh < 0 || static_cast<std::size_t>(node.mesh) >= scene.meshes.size()) return false;
    const Mesh& m = scene.meshes[static_cast<std::size_t>(node.mesh)];
    if (m.morph_deltas.empty()) return false;
    const std::size_t per_key = c.interpolation == AnimationChannel::Interpolation::cubic_spline ? 3 : 1;
    const std::size_t n = c.values.size() / std::max<std::size_t>(1, c.times.size() * per_key);
    std::vector<glm::vec4> rest(n, glm::vec4(0.0f));  // one weight per entry, in x
    for (std::size_t j = 0; j < n; ++j) rest[j].x = j < m.morph_weights.size() ? m.morph_weights[j] : 0.0f;
    return !channel_holds(c, rest);
  }
  // A constant channel moves the node once if its value is not the node's own (frame 0), else never.
  const std::vector<glm::vec4> held = first_values(c, 1);
  const glm::vec4 own = c.path == P::translation ? glm::vec4(node.translation, held[0].w)
                        : c.path == P::scale
                            ? glm::vec4(node.scale, held[0].w)
                            : glm::vec4(node.rotation.x, node.rotation.y, node.rotation.z, node.rotation.w);
  return !channel_holds(c, held) || node.has_matrix || held[0] != own;
}

std::vector<std::uint32_t> deforming_meshes(const Scene& scene) {
  std::vector<std::uint32_t> out;
  for (const MeshDeformer& d : scene.deformers)
    if (d.mesh < scene.meshes.size()) out.push_back(d.mesh);
  const std::vector<char> placing = nodes_placing_instances(scene);
  for (std::uint32_t m = 0; m < scene.meshes.size(); ++m)
    if (const AnimationChannel* c = scene.meshes[m].morph_deltas.empty() ? nullptr : weights_channel_of(scene, m);
        c && channel_moves(scene, *c, placing))
      out.push_back(m);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::vector<float> mesh_morph_weights(const Scene& scene, std::uint32_t mesh, float t) {
  if (mesh >= scene.meshes.size()) return {};
  const Mesh& m = scene.meshes[mesh];
  std::vector<float> w = m.morph_weights;
  if (const AnimationChannel* c = weights_channel_of(scene, mesh)) w = sample_weights(*c, t);
  w.resize(m.morph_deltas.size(), 0.0f);
  return w;
}

std::vector<glm::vec3> posed_positions(const Scene& scene, std::uint32_t mesh, float t) {
  if (mesh >= scene.meshes.size()) return {};
  const Mesh& m = scene.meshes[mesh];
  std::vector<glm::vec3> p =
      m.morph_deltas.empty() ? m.positions : morphed_positions(m, mesh_morph_weights(scene, mesh, t));
  for (const MeshDeformer& d : scene.deformers)
    if (d.mesh == mesh) p = sway(p, d, t);
  return p;
}

std::vector<Triangle> posed_triangles(const Scene& scene, std::uint32_t mesh, float t) {
  if (mesh >= scene.meshes.size()) return {};
  return triangles_over(scene.meshes[mesh], posed_positions(scene, mesh, t));
}

float animation_duration(const Scene& scene) {
  float d = 0.0f;
  for (const Animation& a : scene.animations)
    for (const AnimationChannel& c : a.channels)
      if (!c.times.empty()) d = std::max(d, c.times.back());
  return d;
}

std::size_t rigid_channels_moving(const Scene& scene) {
  const std::vector<char> placing = nodes_placing_instances(scene);
  std::size_t count = 0;
  for (const Animation& a : scene.animations)
    for (const AnimationChannel& c : a.channels)
      count += c.path != AnimationChannel::Path::weights && channel_moves(scene, c, placing);
  return count;
}

bool scene_animates(const Scene& scene) {
  if (!scene.deformers.empty() || !deforming_meshes(scene).empty()) return true;
  return rigid_channels_moving(scene) > 0;
}

void apply_animation(const Animation& anim, float t, std::vector<Node>& nodes, std::vector<bool>& changed) {
  changed.resize(nodes.size(), false);
  for (const AnimationChannel& c : anim.channels) {
    if (c.node < 0 || static_cast<std::size_t>(c.node) >= nodes.size()) continue;
    if (c.path == AnimationChannel::Path::weights) continue;
    Node& n = nodes[c.node];
    const glm::vec4 v = sample_channel(c, t);
    switch (c.path) {
      case AnimationChannel::Path::translation:
        n.translation = glm::vec3(v);
        break;
      case AnimationChannel::Path::rotation:
        n.rotation = glm::normalize(to_quat(v));
        break;
      case AnimationChannel::Path::scale:
        n.scale = glm::vec3(v);
        break;
      case AnimationChannel::Path::weights:
        break;
    }
    n.local = compose_trs(n.translation, n.rotation, n.scale);
    n.has_matrix = false;
    changed[c.node] = true;
  }
}

std::vector<glm::mat4> node_world_transforms(std::span<const Node> nodes) {
  // Composed in double, as the loader does: a chain of 100,000 levels in float drifted (99.956 for 99.999).
  std::vector<glm::dmat4> world(nodes.size());
  std::vector<char> done(nodes.size(), 0);
  // Iterative: walk up to the first computed ancestor, then down.
  std::vector<std::size_t> chain;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    chain.clear();
    std::size_t j = i;
    while (!done[j]) {
      chain.push_back(j);
      const int p = nodes[j].parent;
      if (p < 0 || static_cast<std::size_t>(p) >= nodes.size() || chain.size() > nodes.size()) break;
      j = static_cast<std::size_t>(p);
    }
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      const int p = nodes[*it].parent;
      const bool has_parent = p >= 0 && static_cast<std::size_t>(p) < nodes.size() && done[p];
      world[*it] = has_parent ? world[p] * glm::dmat4(nodes[*it].local) : glm::dmat4(nodes[*it].local);
      done[*it] = 1;
    }
  }
  std::vector<glm::mat4> out(world.size());
  for (std::size_t i = 0; i < world.size(); ++i) out[i] = glm::mat4(world[i]);
  return out;
}

std::vector<glm::vec3> deformed_positions(const Mesh& mesh, const MeshDeformer& d, float t) {
  return sway(mesh.positions, d, t);
}

std::vector<Triangle> deformed_triangles(const Mesh& mesh, const MeshDeformer& d, float t) {
  return triangles_over(mesh, deformed_positions(mesh, d, t));
}

Scene posed_scene(const Scene& scene, float t) {
  Scene out = scene;
  const float duration = animation_duration(scene);
  if (duration > 0.0f) t = std::fmod(std::max(t, 0.0f), duration);
  std::vector<bool> changed;
  for (const Animation& a : scene.animations) apply_animation(a, t, out.nodes, changed);
  if (std::find(changed.begin(), changed.end(), true) != changed.end()) {
    const std::vector<glm::mat4> world = node_world_transforms(out.nodes);
    for (Instance& inst : out.instances)
      if (inst.node < world.size()) inst.transform = world[inst.node];
  }
  for (const std::uint32_t m : deforming_meshes(scene)) out.meshes[m].positions = posed_positions(scene, m, t);
  if (!scene.triangles.empty()) out.flatten();
  return out;
}

SceneAnimator::SceneAnimator(const Scene& scene, Tlas& tlas, const AnimatorOptions& opts)
    : scene_(scene),
      tlas_(tlas),
      opts_(opts),
      nodes_(scene.nodes),
      duration_(animation_duration(scene)),
      deforming_(deforming_meshes(scene)) {
  if (tlas.instances().size() != scene.instances.size())
    throw std::invalid_argument("animator: the two-level structure has " + std::to_string(tlas.instances().size()) +
                                " instances, the scene " + std::to_string(scene.instances.size()));
  transforms_.reserve(scene.instances.size());
  for (const Instance& inst : scene.instances) transforms_.push_back(inst.transform);
}

FrameStats SceneAnimator::step(float t) {
  FrameStats fs;
  fs.frame = frame_++;
  if (duration_ > 0.0f) t = std::fmod(std::max(t, 0.0f), duration_);
  fs.time = t;
  // Rigid motion: only if a channel drives a node.
  std::vector<bool> changed;
  for (const Animation& a : scene_.animations) apply_animation(a, t, nodes_, changed);
  if (std::find(changed.begin(), changed.end(), true) != changed.end()) {
    const std::vector<glm::mat4> world = node_world_transforms(nodes_);
    for (std::size_t i = 0; i < transforms_.size(); ++i) {
      const std::uint32_t n = scene_.instances[i].node;
      if (n >= world.size() || world[n] == transforms_[i]) continue;
      transforms_[i] = world[n];
      ++fs.moved_instances;
    }
    if (fs.moved_instances > 0) {
      fs.tlas_rebuild_ms += tlas_.update_transforms(transforms_).tlas_rebuild_ms;
      fs.tlas_rebuilt = true;
    }
  }
  // Deforming meshes (deformers, morph targets): refit, or rebuild past the ratio.
  for (const std::uint32_t mesh : deforming_) {
    const int b = tlas_.blas_of_mesh(mesh);
    if (b < 0) continue;
    const std::vector<Triangle> tris = posed_triangles(scene_, mesh, t);
    const auto t0 = Clock::now();
    Bvh fresh(tris, tlas_.blas(b).options());
    fs.rebuild_ms += ms_since(t0);
    const TlasUpdateStats us = tlas_.refit_blas(static_cast<std::size_t>(b), tris);
    ++fs.refits;
    fs.refit_ms += us.blas_refit_ms;
    fs.tlas_rebuild_ms += us.tlas_rebuild_ms;
    fs.tlas_rebuilt = true;
    const double sah_refit = tlas_.blas(b).build_stats().sah_cost;
    const double sah_fresh = fresh.build_stats().sah_cost;
    fs.sah_refit += sah_refit;
    fs.sah_rebuilt += sah_fresh;
    if (opts_.rebuild_ratio > 0.0 && sah_refit > opts_.rebuild_ratio * sah_fresh) {
      fs.tlas_rebuild_ms += tlas_.replace_blas(static_cast<std::size_t>(b), std::move(fresh)).tlas_rebuild_ms;
      ++fs.rebuilds;
    }
  }
  if (fs.tlas_rebuilt || !overlap_known_) {
    overlap_ = instance_overlap(tlas_);
    overlap_known_ = true;
  }
  fs.overlap = overlap_;
  return fs;
}

}  // namespace accelviz
