#pragma once
// Playing a scene's motion: sampling glTF TRS channels at a time t (linear,
// with quaternion slerp for rotations; step; cubic spline with in/out
// tangents, glTF 2.0 Appendix C), node world transforms, procedural mesh
// deformation (MeshDeformer), and the per-frame update of a two-level
// structure: rigid motion touches only instance transforms and the TLAS;
// a deforming mesh refits its BLAS, or rebuilds it when the refitted tree's
// SAH exceeds a fresh build's by more than a set ratio (the rule of
// core/analysis/refit_decay.h, applied per BLAS).
#include <cstdint>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <span>
#include <vector>

#include "core/accel/tlas/tlas.h"
#include "core/accel/tlas/tlas_overlap.h"
#include "core/scene/scene.h"

namespace accelviz {

/// Value of CHANNEL at time T (clamped to its first and last key). Vec3
/// paths return xyz (w = 0); rotation returns the unit quaternion as (x, y,
/// z, w), glTF's order. Throws std::invalid_argument for a channel without
/// keys or with a value count that does not match its interpolation.
glm::vec4 sample_channel(const AnimationChannel& channel, float t);

/// Morph weights of a `weights` CHANNEL at time T: one value per morph
/// target (the channel's outputs per key divided by its keys), interpolated
/// like sample_channel (linear, step, cubic spline with in/out tangents;
/// clamped to the first and last key). Throws std::invalid_argument for a
/// channel without keys or with a value count that is not a positive
/// multiple of its keys (times 3 for cubic spline).
std::vector<float> sample_weights(const AnimationChannel& channel, float t);

/// Meshes whose shape changes over time, ascending: those a MeshDeformer
/// moves and those with morph targets whose weights a channel drives (the
/// channel's node references the mesh, and its weights change: channel_moves).
std::vector<std::uint32_t> deforming_meshes(const Scene& scene);

/// Morph weights of MESH at time T: the first `weights` channel (animations
/// in order) whose node references the mesh, sampled at T, else the mesh's
/// default weights. One BLAS per mesh: every instance shares this shape.
/// Sized to the mesh's target count (empty: no targets).
std::vector<float> mesh_morph_weights(const Scene& scene, std::uint32_t mesh, float t);

/// Object-space vertex positions of MESH at time T: morph targets under
/// mesh_morph_weights, then the mesh's deformers on top.
std::vector<glm::vec3> posed_positions(const Scene& scene, std::uint32_t mesh, float t);

/// Object-space triangles of MESH at time T (posed_positions), in index
/// order, skipping the triangles a BLAS skips (non-finite rest vertices).
std::vector<Triangle> posed_triangles(const Scene& scene, std::uint32_t mesh, float t);

/// Last key time over all channels of all animations (0: nothing animates).
float animation_duration(const Scene& scene);

/// For each node: 1 when it places an instance (the instance's own node or
/// one of its ancestors), so that moving it moves geometry.
std::vector<char> nodes_placing_instances(const Scene& scene);

/// True when channel C changes what is traced: its node places an instance
/// (nodes_placing_instances: a channel of a camera, a light, an empty node or
/// a node outside the loaded scene moves no geometry), and its keys do not
/// all hold one value with flat tangents that is the node's own (its rest
/// TRS, or for weights the mesh's default weights). A constant channel whose
/// value differs from the rest pose moves the node once; one on a node given
/// by a matrix always counts (the animation replaces the matrix by TRS).
bool channel_moves(const Scene& scene, const AnimationChannel& c, const std::vector<char>& placing);

/// Node TRS channels that move geometry (channel_moves).
std::size_t rigid_channels_moving(const Scene& scene);

/// True when the scene has node TRS channels that move geometry, mesh
/// deformers, or morph weights channels that change a placed mesh's shape
/// (channel_moves): "no refit without motion".
bool scene_animates(const Scene& scene);

/// Sets the TRS of every node a channel of ANIM drives to its value at T and
/// recomputes those nodes' local matrices (T * R * S). Marks them in
/// `changed` (resized to nodes.size()). Weight channels are not node
/// motion: they shape meshes (mesh_morph_weights, posed_positions).
void apply_animation(const Animation& anim, float t, std::vector<Node>& nodes, std::vector<bool>& changed);

/// The local matrix T * R * S of a node's translation, rotation and scale.
glm::mat4 compose_trs(const glm::vec3& translation, const glm::quat& rotation, const glm::vec3& scale);

/// World (object-to-world) matrix of every node: parent chain of locals.
std::vector<glm::mat4> node_world_transforms(std::span<const Node> nodes);

/// Object-space vertex positions of MESH deformed by D at time T.
std::vector<glm::vec3> deformed_positions(const Mesh& mesh, const MeshDeformer& d, float t);

/// Object-space triangles of MESH deformed by D at time T, in index order.
std::vector<Triangle> deformed_triangles(const Mesh& mesh, const MeshDeformer& d, float t);

/// SCENE as it stands at time T (wrapped into the animation's duration, as
/// SceneAnimator::step does): nodes driven by channels take their sampled
/// TRS, every instance its node's world transform, deformed and morphing meshes their
/// moved vertices (deformers and morph targets); the world triangle list is flattened again when SCENE's
/// was (an instanced scene left unflattened stays so). At T = 0 of a scene
/// whose rest pose is its first key this is SCENE's geometry.
Scene posed_scene(const Scene& scene, float t);

struct AnimatorOptions {
  /// Rebuild a deforming BLAS when refit SAH / fresh SAH exceeds this (> 1);
  /// 0: always refit (the fresh build is still made to report its SAH).
  double rebuild_ratio = 1.3;
};

/// What one frame did and cost.
struct FrameStats {
  std::uint32_t frame = 0;
  float time = 0.0f;
  std::uint32_t moved_instances = 0;  ///< instances whose transform changed this frame
  std::uint32_t refits = 0;           ///< BLAS refits
  std::uint32_t rebuilds = 0;         ///< BLAS rebuilds (the ratio rule fired)
  bool tlas_rebuilt = false;          ///< false when nothing moved
  double tlas_rebuild_ms = 0.0;
  double refit_ms = 0.0;
  double rebuild_ms = 0.0;   ///< fresh BLAS builds (made every frame a mesh deforms, to compare SAH)
  double sah_refit = 0.0;    ///< refitted deforming BLAS (sum over deforming meshes)
  double sah_rebuilt = 0.0;  ///< fresh build on the same vertices (sum)
  /// Instance overlap (tlas_overlap.h) of the instances' world boxes after
  /// this frame's update: measured when the TLAS was rebuilt (and on the
  /// first frame), carried over unchanged when nothing moved. Not part of
  /// any of the timings above.
  InstanceOverlap overlap;
};

/// Drives a Tlas built from SCENE through time. Only what moves is touched:
/// a static scene costs nothing per frame (no TLAS rebuild, no refit).
class SceneAnimator {
 public:
  /// SCENE and TLAS must outlive the animator; TLAS must have been built from SCENE.
  SceneAnimator(const Scene& scene, Tlas& tlas, const AnimatorOptions& opts = {});

  /// Moves everything to time T (seconds, wrapped into the animation's
  /// duration) and updates the structure: instance transforms and the TLAS
  /// when nodes moved, and every deforming mesh's BLAS (deforming_meshes():
  /// procedural deformers and morph targets) by refit, or rebuild past the ratio.
  FrameStats step(float t);

  /// Instance transforms as of the last step.
  std::span<const glm::mat4> instance_transforms() const { return transforms_; }

 private:
  const Scene& scene_;
  Tlas& tlas_;
  AnimatorOptions opts_;
  std::vector<Node> nodes_;
  std::vector<glm::mat4> transforms_;
  std::uint32_t frame_ = 0;
  float duration_ = 0.0f;
  InstanceOverlap overlap_;  ///< as of the last TLAS rebuild
  bool overlap_known_ = false;
  std::vector<std::uint32_t> deforming_;  ///< deforming_meshes(scene)
};

}  // namespace accelviz
