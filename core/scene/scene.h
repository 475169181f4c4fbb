#pragma once
// The in-memory scene: meshes in object space, the node graph and instances
// that place them, and a flattened world-space triangle list that every
// single-level structure indexes. Primitive ids number that list in load
// order: meshes in glTF node order (depth first, scene roots in order),
// triangles in index order.
#include "core/geometry/triangle.h"
#include "core/math/aabb.h"

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace accelviz {

/// Every loader error: the message is one line, "<file>: <problem>".
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Object-space triangle mesh (one glTF mesh, all its triangle primitives merged).
struct Mesh {
  std::string name;
  std::vector<glm::vec3> positions;  ///< the rest pose: morph_base + the default weights' deltas, if any
  std::vector<glm::uvec3> indices;   ///< validated: every index < positions.size()
  /// glTF morph targets (POSITION only): per target one delta per vertex
  /// (zeros where a primitive's target has no POSITION). Empty: no targets.
  std::vector<std::vector<glm::vec3>> morph_deltas;
  /// Default weights, one per target (glTF mesh.weights, or a node's weights; zeros when absent).
  std::vector<float> morph_weights;
  /// Vertex positions before any morph (empty without targets): a pose with
  /// weights w is morph_base + sum_i w_i * morph_deltas[i] (animation.h morphed_positions).
  std::vector<glm::vec3> morph_base;
};

/// MESH's vertex positions under morph WEIGHTS: morph_base + sum_i
/// weights[i] * morph_deltas[i], accumulated in target order (missing weights
/// count as 0, extra ones are ignored). A mesh without targets: its positions.
std::vector<glm::vec3> morphed_positions(const Mesh& mesh, const std::vector<float>& weights);

/// A node of the scene graph. Local transform as TRS (matrix nodes are decomposed
/// only for display; `local` is authoritative).
struct Node {
  std::string name;
  int parent = -1;
  std::vector<int> children;
  glm::mat4 local{1.0f};
  glm::vec3 translation{0.0f};
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 scale{1.0f};
  bool has_matrix = false;  ///< true when glTF gave a matrix instead of TRS
  int mesh = -1;
  int camera = -1;
  int light = -1;
};

/// One placement of a mesh in the world (a node that references it).
struct Instance {
  std::uint32_t mesh = 0;
  std::uint32_t node = 0;
  glm::mat4 transform{1.0f};          ///< object to world
  std::uint32_t first_triangle = 0;   ///< its range in Scene::triangles
  std::uint32_t triangle_count = 0;
};

struct Camera {
  std::string name;
  glm::vec3 position{0.0f, 0.0f, 5.0f};
  glm::vec3 forward{0.0f, 0.0f, -1.0f};  ///< unit
  glm::vec3 up{0.0f, 1.0f, 0.0f};        ///< unit, orthogonal to forward
  float yfov = 0.8f;                     ///< vertical field of view, radians
  float aspect = 0.0f;                   ///< 0: take it from the image size
};

struct Light {
  enum class Kind { point, directional, spot };
  std::string name;
  Kind kind = Kind::point;
  glm::vec3 position{0.0f};
  glm::vec3 direction{0.0f, -1.0f, 0.0f};  ///< unit, the direction light travels
  glm::vec3 color{1.0f};
  float intensity = 1.0f;
  float range = 0.0f;  ///< 0: unlimited
  /// Spot lights' cone (KHR_lights_punctual's defaults 0 and pi/4): kept so that export writes the
  /// cone the file had; the shadow rays aim at the light's position whatever its cone.
  float inner_cone = 0.0f, outer_cone = 0.78539816f;
};

/// glTF animation data, kept as data (sampled by the dynamics code).
struct AnimationChannel {
  enum class Path { translation, rotation, scale, weights };
  enum class Interpolation { linear, step, cubic_spline };
  int node = -1;
  Path path = Path::translation;
  Interpolation interpolation = Interpolation::linear;
  std::vector<float> times;
  std::vector<glm::vec4> values;  ///< vec3 paths use xyz; cubic spline stores in-tangent, value, out-tangent per key
};

struct Animation {
  std::string name;
  std::vector<AnimationChannel> channels;
};

/// A procedural deformation of one mesh (built-in dynamic scenes; glTF has
/// no such thing): at time t every vertex sways horizontally by
/// amplitude * (y / height)^2 * (sin(w), 0, 0.5 cos(w)), w = 2 pi frequency t
/// + 0.7 x + 0.5 z, so vertices at y <= 0 stay put (waving grass).
struct MeshDeformer {
  std::uint32_t mesh = 0;
  float amplitude = 0.05f;
  float frequency = 0.5f;  ///< Hz
  float height = 1.0f;     ///< y at which the sway reaches `amplitude`
};

/// What the loader dropped, skipped or noticed. Never silent.
struct LoadReport {
  std::uint64_t dropped_nonfinite = 0;   ///< triangles with a NaN/inf vertex, removed
  std::uint64_t degenerate = 0;          ///< zero-area triangles, kept
  std::uint64_t skipped_primitives = 0;  ///< points/lines primitives skipped
  std::vector<std::string> warnings;     ///< one line each
};

/// The loaders' error for a scene left without triangles: "scene contains no
/// triangles", followed by what the loader removed on the way when it removed
/// something, e.g. " (1 triangle dropped: a NaN or infinite vertex)".
std::string no_triangles_message(const LoadReport& report);

struct Scene {
  std::string source;  ///< file path or built-in spec it came from
  std::vector<Mesh> meshes;
  std::vector<Node> nodes;
  std::vector<int> roots;
  std::vector<Instance> instances;
  std::vector<Triangle> triangles;  ///< world space, primitive id = index
  std::vector<Camera> cameras;
  std::vector<Light> lights;
  std::vector<Animation> animations;
  std::vector<MeshDeformer> deformers;
  LoadReport report;

  /// Bounds of all world-space triangles (empty box for an empty scene); for
  /// an instanced scene left unflattened (triangles empty), the instances'
  /// transformed mesh boxes.
  Aabb bounds() const;
  /// True when some mesh with triangles is referenced by more than one instance.
  bool has_instancing() const;
  /// Triangles the instances expand to: each instance's mesh triangles, as
  /// flatten() would make them before dropping non-finite ones (so for a
  /// flattened scene triangles.size() + report.dropped_nonfinite). Counted
  /// also when the scene is too large to flatten (builtin:island).
  std::uint64_t instanced_triangle_count() const;
  /// Triangles of the meshes some instance references, each mesh once: what
  /// a two-level structure's BLASes are built from.
  std::uint64_t unique_triangle_count() const;
  /// Meshes some instance references.
  std::size_t referenced_mesh_count() const;
  /// False for a scene left unflattened because it is too large
  /// (`triangles` empty though its instances have triangles).
  bool flattened() const { return !triangles.empty() || instanced_triangle_count() == 0; }
  /// Rebuilds `triangles` and every instance's range from meshes + instances,
  /// dropping non-finite triangles (counted in report) and counting degenerate ones.
  void flatten();
};

/// A scene's triangle count in words (`accelviz info`, the app's Scene
/// panel): the world triangles; with instancing, "N (from U unique in M
/// meshes)"; for a scene too large to flatten, "N instanced, not flattened
/// (U unique in M meshes)".
std::string triangle_count_text(const Scene& scene);

}  // namespace accelviz
