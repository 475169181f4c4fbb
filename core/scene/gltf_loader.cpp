// glTF 2.0 loading: tinygltf parses, we validate what it does not and build
// the Scene.
//
// tinygltf (Debian 2.7.0) checks the JSON syntax and the presence of required
// properties, but not that indices point inside their arrays, that accessors
// fit in their buffer views, that index values address existing vertices, or
// that the node graph is a forest. Its GLB reader also trusts a BIN chunk
// length up to 8 bytes past the end of the file. So the steps are:
//   1. read the file ourselves (clear "no such file"/size errors), and for a
//      .glb validate the header and every chunk length against the file;
//   2. a SAX pass over the JSON (no DOM): syntax errors, nesting depth, and
//      `extensionsRequired`, checked before tinygltf can fail on a Draco or
//      meshopt primitive with a misleading message;
//   3. tinygltf builds its Model (image decoding replaced by a no-op: we never
//      draw textures, and decoding is slow and a source of failures);
//   4. our validation and conversion: meshes, node forest, transforms,
//      cameras, lights, animations;
//   5. Scene::flatten() builds world triangles, dropping non-finite ones.
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "core/scene/load.h"
#include "core/util/file_checks.h"
#include "core/util/one_line.h"
#define GLM_ENABLE_EXPERIMENTAL
#include <glm/gtx/matrix_decompose.hpp>
#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

namespace accelviz {
namespace {

namespace fs = std::filesystem;

/// Flattening instances multiplies triangles; a small file can ask for
/// billions (10,000 nodes × a 1M-triangle mesh). Refuse beyond this many
/// world triangles (about 9.6 GB of Triangle) rather than run out of memory.
constexpr std::uint64_t kMaxWorldTriangles = std::uint64_t{1} << 28;
/// glTF needs perhaps 10 levels; anything this deep is hostile or broken.
constexpr std::size_t kMaxJsonDepth = 256;
/// tinygltf takes the file size as `unsigned int`; GLB lengths are 32-bit.
constexpr std::uint64_t kMaxFileBytes = std::numeric_limits<std::uint32_t>::max();
/// The problem named for a file (the scene, or a buffer or image it names) over kMaxFileBytes.
constexpr std::string_view kTooLarge = "file is larger than 4 GiB, which glTF loading does not support";

constexpr std::uint32_t kGlbMagic = 0x46546C67;      // "glTF"
constexpr std::uint32_t kGlbChunkJson = 0x4E4F534A;  // "JSON"
constexpr std::uint32_t kGlbChunkBin = 0x004E4942;   // "BIN\0"

/// Every line of a message, each made one line (tinygltf warnings come joined).
std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find_first_of("\r\n", start);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(start, end - start);
    if (line.find_first_not_of(" \t") != std::string::npos) out.push_back(first_line(line));
    start = end + 1;
  }
  return out;
}

std::uint32_t read_u32_le(const unsigned char* p) {
  return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
}

std::string hex32(std::uint32_t v) {
  static const char* digits = "0123456789abcdef";
  std::string s = "0x";
  for (int shift = 28; shift >= 0; shift -= 4) s += digits[(v >> shift) & 0xF];
  return s;
}

// --- Step 2: SAX pre-pass over the JSON ------------------------------------

/// Walks the JSON without building it: records the first syntax error, stops
/// at absurd nesting, collects the top-level `extensionsRequired` strings and
/// type-checks what tinygltf reads loosely (negative indices and counts, the
/// number arrays of nodes and meshes).
class JsonPrecheck final : public nlohmann::json_sax<nlohmann::json> {
 public:
  std::vector<std::string> required;
  std::string error;                  ///< empty when the JSON is acceptable
  std::vector<std::string> warnings;  ///< what the file breaks that tinygltf reads past in silence

  bool null() override { return element(false) && value(); }
  bool boolean(bool) override { return element(false) && value(); }
  bool number_integer(number_integer_t v) override {
    if (!element(true)) return false;
    // tinygltf silently ignores a negative index, offset, length or count
    // (keeping its default 0), which would load other bytes than the file
    // names; reject them here (found by tests/core/test_malformed_files.cpp).
    if (v < 0 && is_unsigned_key(last_key_) && !in_extras()) {
      error = "invalid glTF: negative " + last_key_ + " (" + std::to_string(v) + ")";
      return false;
    }
    return value();
  }
  bool number_unsigned(number_unsigned_t v) override {
    if (!element(true)) return false;
    // tinygltf keeps an index in an int: 2^32 wrapped to 0 (another mesh, node or accessor than the file names).
    if (v > 0x7FFFFFFFu && is_index_key()) {
      error = "invalid glTF: \"" + last_key_ + "\" " + std::to_string(v) + " is beyond any index (2^31 - 1)";
      return false;
    }
    return value();
  }
  bool number_float(number_float_t, const string_t& text) override {
    if (!element(true)) return false;
    // tinygltf skips a fractional or float-typed index ("mesh": 0.0, "indices": 1.0): the node lost its mesh,
    // the primitive its index buffer, with nothing said.
    if (is_index_key()) {
      error = "invalid glTF: \"" + last_key_ + "\" is " + text.substr(0, 40) +
              ": an index is a whole number written without a point or exponent";
      return false;
    }
    return value();
  }
  bool binary(binary_t&) override { return element(false) && value(); }
  bool string(string_t& s) override {
    if (!element(false)) return false;
    if (is_unsigned_key(last_key_) && !in_extras()) {
      error = "invalid glTF: \"" + last_key_ + "\" is the string \"" + s.substr(0, 40) + "\", not a number";
      return false;
    }
    if (frames_.size() == 2 && frames_[1].array && frames_[0].key == "extensionsRequired") required.push_back(s);
    return value();
  }
  bool start_object(std::size_t) override { return element(false) && open(true); }
  bool end_object() override {
    // A node's object closes: tinygltf skips translation/rotation/scale once it read a matrix.
    if (in_node_object() && node_matrix_ && node_trs_)
      warnings.push_back(
          "node " + std::to_string(frames_[1].elements - 1) +
          " has both a matrix and translation/rotation/scale, which glTF 2.0 forbids; the matrix is used");
    if (in_node_object()) node_matrix_ = node_trs_ = false;
    return close();
  }
  bool start_array(std::size_t) override { return element(false, true) && open(false); }
  bool end_array() override { return close(); }
  bool key(string_t& k) override {
    last_key_ = k;
    if (!frames_.empty()) frames_.back().key = k;
    if (in_node_object()) {
      node_matrix_ = node_matrix_ || k == "matrix";
      node_trs_ = node_trs_ || k == "translation" || k == "rotation" || k == "scale";
    }
    return true;
  }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception& ex) override {
    // nlohmann prefixes "[json.exception.parse_error.101] "; the rest reads well.
    std::string what = ex.what();
    if (!what.empty() && what[0] == '[') {
      const auto close_bracket = what.find("] ");
      if (close_bracket != std::string::npos) what = what.substr(close_bracket + 2);
    }
    error = "malformed JSON: " + what;
    return false;
  }

 private:
  /// Inside free-form "extras", where any key name may hold any value.
  bool in_extras() const {
    for (const Frame& f : frames_)
      if (f.key == "extras") return true;
    return false;
  }
  /// The value belongs to an index or enum (tinygltf's int fields): not a byte size or count, which it
  /// reads as size_t and checks itself, and not inside "extras".
  bool is_index_key() const {
    const std::string& k = last_key_;
    return is_unsigned_key(k) && k != "byteOffset" && k != "byteLength" && k != "count" && !in_extras();
  }
  static bool is_unsigned_key(const std::string& k) {
    static const char* const keys[] = {
        "byteOffset", "byteLength", "byteStride", "count",    "buffer",    "bufferView", "componentType",
        "mode",       "indices",    "material",   "mesh",     "camera",    "skin",       "node",
        "scene",      "children",   "nodes",      "joints",   "sampler",   "source",     "input",
        "output",     "index",      "texCoord",   "light",    "POSITION",  "NORMAL",     "TANGENT",
        "TEXCOORD_0", "TEXCOORD_1", "COLOR_0",    "JOINTS_0", "WEIGHTS_0", "target"};
    for (const char* key : keys)
      if (k == key) return true;
    return false;
  }
  std::string last_key_;  ///< the most recent key at any depth (the one a scalar or array element belongs to)
  bool node_matrix_ = false, node_trs_ = false;  ///< keys of the node object open now
  /// Directly inside one of "nodes"' objects.
  bool in_node_object() const {
    return frames_.size() == 3 && frames_[0].key == "nodes" && frames_[1].array && !frames_[2].array;
  }

  /// An open object or array: its current key, or how many elements it has begun.
  struct Frame {
    bool array = false;
    std::size_t elements = 0;
    std::string key;
  };
  std::vector<Frame> frames_;  ///< the open containers, the root first

  /// Called for every value before it opens: counts array elements and
  /// type-checks the number arrays of nodes and meshes, which tinygltf reads
  /// loosely (`"rotation": "abc"` as no rotation; a string inside a matrix
  /// skipped, so the matrix is reported one number short).
  bool element(bool is_number, bool is_array = false) {
    const std::size_t d = frames_.size();
    std::size_t position = 0;
    if (d > 0 && frames_.back().array) position = frames_.back().elements++;
    if (d < 3 || d > 4 || !frames_[1].array || frames_[2].array) return true;
    const std::string& list = frames_[0].key;
    const std::string& field = frames_[2].key;
    const bool node = list == "nodes";
    const bool checked = node ? (field == "matrix" || field == "translation" || field == "rotation" ||
                                 field == "scale" || field == "weights")
                              : list == "meshes" && field == "weights";
    if (!checked) return true;
    const std::string owner = (node ? "node " : "mesh ") + std::to_string(frames_[1].elements - 1);
    if (d == 3 && !is_array)
      error = "invalid glTF: " + owner + ": \"" + field + "\" is not an array of numbers";
    else if (d == 4 && !is_number)
      error = "invalid glTF: " + owner + ": \"" + field + "\" has a non-number at item " + std::to_string(position);
    return error.empty();
  }

  bool value() {
    if (frames_.empty()) {
      error = "malformed glTF: the JSON root is not an object";
      return false;
    }
    return true;
  }
  bool open(bool is_object) {
    if (frames_.empty() && !is_object) return value();
    if (frames_.size() + 1 > kMaxJsonDepth) {
      error = "malformed glTF: JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels";
      return false;
    }
    frames_.push_back(Frame{!is_object, 0, {}});
    return true;
  }
  bool close() {
    frames_.pop_back();
    return true;
  }
};

/// Extensions whose absence of support cannot change the geometry we trace:
/// lights we read; materials and texture transforms we ignore (we draw no
/// materials); quantised *positions* are rejected at the accessor, so
/// KHR_mesh_quantization is fine for every other attribute.
bool required_extension_supported(const std::string& name) {
  return name == "KHR_lights_punctual" || name == "KHR_mesh_quantization" || name == "KHR_texture_transform" ||
         name == "KHR_texture_basisu" || name == "EXT_texture_webp" || name.rfind("KHR_materials_", 0) == 0;
}

// --- Step 4: validation and conversion -------------------------------------

const char* component_type_name(int type) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: return "BYTE";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return "UNSIGNED_BYTE";
    case TINYGLTF_COMPONENT_TYPE_SHORT: return "SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return "UNSIGNED_SHORT";
    case TINYGLTF_COMPONENT_TYPE_INT: return "INT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return "UNSIGNED_INT";
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return "FLOAT";
    case TINYGLTF_COMPONENT_TYPE_DOUBLE: return "DOUBLE";
    default: return "unknown";
  }
}

const char* type_name(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return "SCALAR";
    case TINYGLTF_TYPE_VEC2: return "VEC2";
    case TINYGLTF_TYPE_VEC3: return "VEC3";
    case TINYGLTF_TYPE_VEC4: return "VEC4";
    case TINYGLTF_TYPE_MAT2: return "MAT2";
    case TINYGLTF_TYPE_MAT3: return "MAT3";
    case TINYGLTF_TYPE_MAT4: return "MAT4";
    default: return "unknown";
  }
}

const char* mode_name(int mode) {
  switch (mode) {
    case TINYGLTF_MODE_POINTS: return "POINTS";
    case TINYGLTF_MODE_LINE: return "LINES";
    case TINYGLTF_MODE_LINE_LOOP: return "LINE_LOOP";
    case TINYGLTF_MODE_LINE_STRIP: return "LINE_STRIP";
    default: return "unknown";
  }
}

std::size_t component_size(int type) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_INT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    case TINYGLTF_COMPONENT_TYPE_DOUBLE: return 8;
    default: return 0;
  }
}

std::size_t component_count(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4:
    case TINYGLTF_TYPE_MAT2: return 4;
    case TINYGLTF_TYPE_MAT3: return 9;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
  }
}

/// A validated window onto an accessor's bytes: element i starts at
/// base + i * stride and all `count` elements lie inside the buffer.
struct AccessorView {
  const unsigned char* base = nullptr;
  std::size_t count = 0;
  std::size_t stride = 0;
  int component_type = 0;
  int type = 0;
  bool normalized = false;

  const unsigned char* element(std::size_t i) const { return base + i * stride; }
};

/// Component k of element i as float: floats as they are, integers
/// normalised as the glTF spec prescribes (max(c / MAX, -1) for signed types).
float read_normalized(const AccessorView& v, std::size_t i, std::size_t k) {
  const unsigned char* p = v.element(i) + k * component_size(v.component_type);
  switch (v.component_type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float f;
      std::memcpy(&f, p, 4);
      return f;
    }
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      std::int8_t c;
      std::memcpy(&c, p, 1);
      return std::max(float(c) / 127.0f, -1.0f);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return float(*p) / 255.0f;
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      std::int16_t c;
      std::memcpy(&c, p, 2);
      return std::max(float(c) / 32767.0f, -1.0f);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      std::uint16_t c;
      std::memcpy(&c, p, 2);
      return float(c) / 65535.0f;
    }
    default: return 0.0f;  // callers check the component type first
  }
}

glm::mat4 column_major(const std::vector<double>& m) {
  glm::mat4 out(1.0f);
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) out[c][r] = float(m[std::size_t(c * 4 + r)]);
  return out;
}

bool finite_matrix(const glm::mat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

class GltfConverter {
 public:
  GltfConverter(const std::string& path, const tinygltf::Model& model, Scene& scene)
      : path_(path), model_(model), scene_(scene) {}

  void run() {
    check_mesh_triangle_count();
    convert_meshes();
    convert_nodes();
    validate_forest();
    const std::vector<int> roots = choose_roots();
    scene_.roots = roots;
    traverse(roots);
    convert_animations();
    warn_ignored_extensions();
    // tinygltf reads any version; a major version other than 2 is another format.
    if (const std::string& v = model_.asset.version; !v.starts_with("2.") && v != "2")
      warn("asset.version is '" + v + "', not 2.x; read as glTF 2.0");
    check_world_triangle_count();
    scene_.flatten();
    if (scene_.triangles.empty()) fail(no_triangles_message(scene_.report));
    cap_warnings();
  }

 private:
  [[noreturn]] void fail(const std::string& problem) const { throw SceneError(path_ + ": " + first_line(problem)); }
  void warn(const std::string& message) { scene_.report.warnings.push_back(first_line(message)); }

  // --- accessors -----------------------------------------------------------

  /// Resolves accessor `index` for `what` and proves that every element lies
  /// inside its buffer view and the view inside its buffer, in arithmetic
  /// that cannot overflow. Nothing is allocated from `count` before this.
  AccessorView view_accessor(int index, const std::string& what) const {
    const auto& accessors = model_.accessors;
    if (index < 0 || std::size_t(index) >= accessors.size())
      fail(what + " refers to accessor " + std::to_string(index) + ", but the file has " +
           std::to_string(accessors.size()) + " accessors");
    const tinygltf::Accessor& acc = accessors[std::size_t(index)];
    const std::string name = "accessor " + std::to_string(index) + " (" + what + ")";
    if (acc.sparse.isSparse) fail(name + " uses sparse storage, which is not supported");
    const std::size_t comp = component_size(acc.componentType);
    const std::size_t ncomp = component_count(acc.type);
    if (comp == 0 || ncomp == 0) fail(name + " has an invalid component type or type");
    const std::size_t elem = comp * ncomp;

    AccessorView view;
    view.component_type = acc.componentType;
    view.type = acc.type;
    view.normalized = acc.normalized;
    if (acc.count == 0) return view;
    if (acc.bufferView < 0)
      fail(name + " has no bufferView (implicit all-zero accessors are not supported)");
    if (std::size_t(acc.bufferView) >= model_.bufferViews.size())
      fail(name + " refers to bufferView " + std::to_string(acc.bufferView) + ", but the file has " +
           std::to_string(model_.bufferViews.size()) + " bufferViews");
    const tinygltf::BufferView& bv = model_.bufferViews[std::size_t(acc.bufferView)];
    const std::string bv_name = "bufferView " + std::to_string(acc.bufferView);
    if (bv.buffer < 0 || std::size_t(bv.buffer) >= model_.buffers.size())
      fail(bv_name + " refers to buffer " + std::to_string(bv.buffer) + ", but the file has " +
           std::to_string(model_.buffers.size()) + " buffers");
    const std::size_t buffer_size = model_.buffers[std::size_t(bv.buffer)].data.size();
    if (bv.byteOffset > buffer_size || bv.byteLength > buffer_size - bv.byteOffset)
      fail(bv_name + " spans bytes [" + std::to_string(bv.byteOffset) + ", " +
           std::to_string(bv.byteOffset) + " + " + std::to_string(bv.byteLength) + ") but buffer " +
           std::to_string(bv.buffer) + " has " + std::to_string(buffer_size) + " bytes");

    const std::size_t stride = bv.byteStride != 0 ? bv.byteStride : elem;
    if (stride < elem)
      fail(name + ": byteStride " + std::to_string(stride) + " of " + bv_name + " is smaller than the element size " +
           std::to_string(elem));
    // byteOffset + stride*(count-1) + elem <= byteLength, tested piecewise so
    // that a count near 2^64 cannot wrap around.
    const std::size_t length = bv.byteLength;
    const bool fits = acc.byteOffset <= length && elem <= length - acc.byteOffset &&
                      acc.count - 1 <= (length - acc.byteOffset - elem) / stride;
    if (!fits)
      fail(name + ": " + std::to_string(acc.count) + " elements of " + std::to_string(elem) + " bytes at stride " +
           std::to_string(stride) + " from byteOffset " + std::to_string(acc.byteOffset) + " do not fit in " +
           bv_name + " (" + std::to_string(length) + " bytes)");

    view.base = model_.buffers[std::size_t(bv.buffer)].data.data() + bv.byteOffset + acc.byteOffset;
    view.count = acc.count;
    view.stride = stride;
    return view;
  }

  std::vector<glm::vec3> read_positions(int index, const std::string& what) const {
    const AccessorView v = view_accessor(index, what);
    const std::string name = "accessor " + std::to_string(index) + " (" + what + ")";
    if (v.type != TINYGLTF_TYPE_VEC3) fail(name + " has type " + type_name(v.type) + " (expected VEC3)");
    if (v.component_type != TINYGLTF_COMPONENT_TYPE_FLOAT) {
      const bool quantized = v.component_type != TINYGLTF_COMPONENT_TYPE_DOUBLE;
      fail(name + " has component type " + component_type_name(v.component_type) +
           (quantized ? " (quantized positions, KHR_mesh_quantization, are not supported; expected FLOAT)"
                      : " (expected FLOAT)"));
    }
    std::vector<glm::vec3> out(v.count);
    for (std::size_t i = 0; i < v.count; ++i) std::memcpy(&out[i], v.element(i), sizeof(glm::vec3));
    return out;
  }

  std::vector<std::uint32_t> read_indices(int index, const std::string& what) const {
    const AccessorView v = view_accessor(index, what);
    const std::string name = "accessor " + std::to_string(index) + " (" + what + ")";
    if (v.type != TINYGLTF_TYPE_SCALAR) fail(name + " has type " + type_name(v.type) + " (expected SCALAR)");
    std::vector<std::uint32_t> out(v.count);
    switch (v.component_type) {
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        for (std::size_t i = 0; i < v.count; ++i) out[i] = *v.element(i);
        break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
        for (std::size_t i = 0; i < v.count; ++i) {
          std::uint16_t x;
          std::memcpy(&x, v.element(i), 2);
          out[i] = x;
        }
        break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        for (std::size_t i = 0; i < v.count; ++i) std::memcpy(&out[i], v.element(i), 4);
        break;
      default:
        fail(name + " has component type " + component_type_name(v.component_type) +
             " (expected UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT)");
    }
    return out;
  }

  // --- meshes --------------------------------------------------------------

  /// Every glTF mesh becomes one Mesh (same index), its triangle primitives
  /// merged; strips and fans are unrolled in the order the spec gives.
  void convert_meshes() {
    scene_.meshes.reserve(model_.meshes.size());
    for (std::size_t m = 0; m < model_.meshes.size(); ++m) {
      const tinygltf::Mesh& gm = model_.meshes[m];
      Mesh mesh;
      mesh.name = gm.name;
      const std::string mesh_where = "mesh " + std::to_string(m);
      // Morph targets (POSITION deltas only): kept unless one is stored in a
      // way we do not read, then the base shape is used, as before.
      bool morphs = has_any_target(gm);
      if (morphs) {
        for (const tinygltf::Primitive& prim : gm.primitives)
          for (const auto& target : prim.targets) {
            const auto it = target.find("POSITION");
            if (it != target.end() && it->second >= 0 && std::size_t(it->second) < model_.accessors.size() &&
                model_.accessors[std::size_t(it->second)].sparse.isSparse && morphs) {
              warn(mesh_where + " has a sparse morph target; its morph targets are ignored (base shape used)");
              morphs = false;
            }
          }
      }
      std::size_t targets = 0;
      for (std::size_t p = 0; p < gm.primitives.size(); ++p) {
        const tinygltf::Primitive& prim = gm.primitives[p];
        const std::string where = "mesh " + std::to_string(m) + " primitive " + std::to_string(p);
        const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
        if (mode >= TINYGLTF_MODE_POINTS && mode <= TINYGLTF_MODE_LINE_STRIP) {
          ++scene_.report.skipped_primitives;
          warn(where + ": mode " + mode_name(mode) + " skipped (only triangles are traced)");
          continue;
        }
        if (mode > TINYGLTF_MODE_TRIANGLE_FAN) fail(where + " has unknown mode " + std::to_string(mode));
        const auto pos = prim.attributes.find("POSITION");
        if (pos == prim.attributes.end()) {
          warn(where + " has no POSITION attribute; skipped");
          continue;
        }
        const std::size_t first_vertex = mesh.positions.size();
        append_primitive(mesh, prim, mode, pos->second, where);
        if (morphs && !prim.targets.empty()) append_morph_targets(mesh, prim, first_vertex, targets, where);
      }
      if (morphs && targets > 0) finish_morph_targets(mesh, gm, mesh_where);
      else if (!gm.weights.empty() && !has_any_target(gm))
        warn(mesh_where + " has " + std::to_string(gm.weights.size()) +
             " default morph weights but no morph targets; ignored");
      scene_.meshes.push_back(std::move(mesh));
    }
  }

  /// POSITION deltas of PRIM's morph targets, for the vertices it appended
  /// from FIRST_VERTEX on. Every primitive of a mesh must have the same
  /// number of targets (glTF 2.0 §3.7.2.2); a target without POSITION moves nothing.
  void append_morph_targets(Mesh& mesh, const tinygltf::Primitive& prim, std::size_t first_vertex,
                            std::size_t& targets, const std::string& where) {
    if (targets == 0) {
      targets = prim.targets.size();
      mesh.morph_deltas.resize(targets);
    } else if (prim.targets.size() != targets) {
      fail(where + " has " + std::to_string(prim.targets.size()) + " morph targets, an earlier primitive of its mesh " +
           std::to_string(targets));
    }
    const std::size_t count = mesh.positions.size() - first_vertex;
    for (std::size_t t = 0; t < targets; ++t) {
      std::vector<glm::vec3>& deltas = mesh.morph_deltas[t];
      deltas.resize(mesh.positions.size(), glm::vec3(0.0f));
      const auto it = prim.targets[t].find("POSITION");
      if (it == prim.targets[t].end()) continue;
      const std::vector<glm::vec3> d =
          read_positions(it->second, "POSITION of morph target " + std::to_string(t) + " of " + where);
      if (d.size() != count)
        fail(where + ": morph target " + std::to_string(t) + " has " + std::to_string(d.size()) +
             " POSITION deltas for " + std::to_string(count) + " vertices");
      for (std::size_t i = 0; i < count; ++i) {
        if (!std::isfinite(d[i].x) || !std::isfinite(d[i].y) || !std::isfinite(d[i].z))
          fail(where + ": morph target " + std::to_string(t) + " has a non-finite delta at vertex " + std::to_string(i));
        deltas[first_vertex + i] = d[i];
      }
    }
  }

  static bool has_any_target(const tinygltf::Mesh& gm) {
    for (const tinygltf::Primitive& prim : gm.primitives)
      if (!prim.targets.empty()) return true;
    return false;
  }

  /// Pads the deltas of primitives without targets, takes the default
  /// weights (mesh.weights) and sets the rest pose to base + their deltas.
  void finish_morph_targets(Mesh& mesh, const tinygltf::Mesh& gm, const std::string& where) {
    for (std::vector<glm::vec3>& d : mesh.morph_deltas) d.resize(mesh.positions.size(), glm::vec3(0.0f));
    const std::size_t targets = mesh.morph_deltas.size();
    mesh.morph_weights.assign(targets, 0.0f);
    if (!gm.weights.empty()) {
      if (gm.weights.size() != targets)
        fail(where + " has " + std::to_string(gm.weights.size()) + " default weights for " + std::to_string(targets) +
             " morph targets");
      for (std::size_t t = 0; t < targets; ++t) {
        if (!std::isfinite(gm.weights[t])) fail(where + " has a non-finite default weight " + std::to_string(t));
        mesh.morph_weights[t] = static_cast<float>(gm.weights[t]);
      }
    }
    mesh.morph_base = mesh.positions;
    mesh.positions = morphed_positions(mesh, mesh.morph_weights);
  }

  void append_primitive(Mesh& mesh, const tinygltf::Primitive& prim, int mode, int position_accessor,
                        const std::string& where) {
    std::vector<glm::vec3> positions = read_positions(position_accessor, "POSITION of " + where);
    const std::size_t vertex_count = positions.size();
    const std::size_t base = mesh.positions.size();
    if (vertex_count > std::numeric_limits<std::uint32_t>::max() - base)
      fail(where + " takes its mesh past 2^32 vertices");

    std::vector<std::uint32_t> indices;
    const bool indexed = prim.indices >= 0;
    if (indexed) {
      indices = read_indices(prim.indices, "indices of " + where);
      for (std::size_t i = 0; i < indices.size(); ++i)
        if (indices[i] >= vertex_count)
          fail("index " + std::to_string(indices[i]) + " at position " + std::to_string(i) + " of accessor " +
               std::to_string(prim.indices) + " is out of range (" + where + " has " + std::to_string(vertex_count) +
               " vertices)");
    }
    const std::size_t n = indexed ? indices.size() : vertex_count;
    auto at = [&](std::size_t i) { return std::uint32_t(base) + (indexed ? indices[i] : std::uint32_t(i)); };

    mesh.positions.insert(mesh.positions.end(), positions.begin(), positions.end());
    if (n < 3) {
      if (n > 0) warn(where + " has fewer than 3 vertices; no triangles");
      return;
    }
    switch (mode) {
      case TINYGLTF_MODE_TRIANGLES:
        if (n % 3 != 0) warn(where + ": " + std::to_string(n % 3) + " trailing vertices ignored (count not a multiple of 3)");
        mesh.indices.reserve(mesh.indices.size() + n / 3);
        for (std::size_t i = 0; i + 2 < n; i += 3) mesh.indices.emplace_back(at(i), at(i + 1), at(i + 2));
        break;
      case TINYGLTF_MODE_TRIANGLE_STRIP:
        // glTF 2.0 §3.7.2.1: p_i = {v_i, v_{i+(1+i%2)}, v_{i+(2-i%2)}}, which
        // keeps every triangle's winding consistent.
        mesh.indices.reserve(mesh.indices.size() + n - 2);
        for (std::size_t i = 0; i + 2 < n; ++i)
          mesh.indices.emplace_back(at(i), at(i + 1 + i % 2), at(i + 2 - i % 2));
        break;
      case TINYGLTF_MODE_TRIANGLE_FAN:
        // glTF 2.0 §3.7.2.1: p_i = {v_{i+1}, v_{i+2}, v_0}.
        mesh.indices.reserve(mesh.indices.size() + n - 2);
        for (std::size_t i = 0; i + 2 < n; ++i) mesh.indices.emplace_back(at(i + 1), at(i + 2), at(0));
        break;
    }
  }

  // --- nodes ---------------------------------------------------------------

  /// Copies nodes with their local transforms; references are checked here
  /// so that traversal can index freely.
  void convert_nodes() {
    const std::size_t n = model_.nodes.size();
    scene_.nodes.resize(n);
    local_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const tinygltf::Node& g = model_.nodes[i];
      Node& node = scene_.nodes[i];
      const std::string name = "node " + std::to_string(i);
      node.name = g.name;
      node.children = g.children;
      if (g.mesh >= 0 && std::size_t(g.mesh) >= model_.meshes.size())
        fail(name + " refers to mesh " + std::to_string(g.mesh) + ", but the file has " +
             std::to_string(model_.meshes.size()) + " meshes");
      if (g.camera >= 0 && std::size_t(g.camera) >= model_.cameras.size())
        fail(name + " refers to camera " + std::to_string(g.camera) + ", but the file has " +
             std::to_string(model_.cameras.size()) + " cameras");
      node.mesh = g.mesh < 0 ? -1 : g.mesh;
      if (!g.weights.empty()) node_morph_weights(i, g);
      if (g.skin >= 0) warn(name + " is skinned; its mesh is used in the bind pose");

      if (!g.matrix.empty()) {
        if (g.matrix.size() != 16)
          fail(name + " has a matrix of " + std::to_string(g.matrix.size()) + " numbers (expected 16)");
        node.local = column_major(g.matrix);
        // glTF requires an affine matrix (last row 0, 0, 0, 1): vertices are
        // transformed as points without a division, so a projective part is
        // ignored; say so rather than draw something else silently.
        if (node.local[0][3] != 0.0f || node.local[1][3] != 0.0f || node.local[2][3] != 0.0f ||
            node.local[3][3] != 1.0f)
          warn(name +
               " has a matrix whose last row is not (0, 0, 0, 1); glTF allows only affine matrices, "
               "so its projective part is ignored");
        node.has_matrix = true;
        decompose_for_display(node);
      } else {
        if (!g.translation.empty() && g.translation.size() != 3)
          fail(name + " has a translation of " + std::to_string(g.translation.size()) + " numbers (expected 3)");
        if (!g.rotation.empty() && g.rotation.size() != 4)
          fail(name + " has a rotation of " + std::to_string(g.rotation.size()) + " numbers (expected 4)");
        if (!g.scale.empty() && g.scale.size() != 3)
          fail(name + " has a scale of " + std::to_string(g.scale.size()) + " numbers (expected 3)");
        if (!g.translation.empty()) node.translation = glm::vec3(g.translation[0], g.translation[1], g.translation[2]);
        if (!g.rotation.empty()) {
          // glTF stores (x, y, z, w); glm's constructor takes w first.
          glm::quat q(float(g.rotation[3]), float(g.rotation[0]), float(g.rotation[1]), float(g.rotation[2]));
          // The spec requires unit quaternions. Rounding-level deviations are
          // left alone: renormalising would change bits and break exact
          // write/load round trips. Clearly non-unit ones are repaired.
          const float len = glm::length(q);
          if (!(len > 0.0f) || !std::isfinite(len)) {
            warn(name + " has a zero or non-finite rotation; identity used");
            q = glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
          } else if (std::fabs(len - 1.0f) > 1e-3f) {
            warn(name + " has a rotation of length " + std::to_string(len) + "; normalised");
            q = q / len;
          }
          node.rotation = q;
        }
        if (!g.scale.empty()) node.scale = glm::vec3(g.scale[0], g.scale[1], g.scale[2]);
        node.local = glm::translate(glm::mat4(1.0f), node.translation) * glm::mat4_cast(node.rotation) *
                     glm::scale(glm::mat4(1.0f), node.scale);
      }
      if (!finite_matrix(node.local)) fail(name + " has a non-finite transform");
      local_[i] = node.local;

      // KHR_lights_punctual: {"extensions": {"KHR_lights_punctual": {"light": i}}}.
      node_light_.push_back(-1);
      const auto ext = g.extensions.find("KHR_lights_punctual");
      if (ext != g.extensions.end() && ext->second.IsObject() && ext->second.Has("light")) {
        const tinygltf::Value& v = ext->second.Get("light");
        const int light = v.IsNumber() ? v.GetNumberAsInt() : -1;
        if (light < 0 || std::size_t(light) >= model_.lights.size())
          fail(name + " refers to light " + (v.IsNumber() ? std::to_string(light) : std::string("(not a number)")) +
               ", but the file has " + std::to_string(model_.lights.size()) + " KHR_lights_punctual lights");
        node_light_.back() = light;
      }
    }
    warn_unweighted_instances();
  }

  /// One shape per mesh: a node of a morphing mesh without weights of its own gets the weights
  /// another node gave the mesh, not the mesh's defaults. Said once per mesh where they differ.
  void warn_unweighted_instances() {
    std::vector<bool> warned(scene_.meshes.size(), false);
    for (std::size_t i = 0; i < model_.nodes.size(); ++i) {
      const tinygltf::Node& g = model_.nodes[i];
      if (g.mesh < 0 || !g.weights.empty()) continue;
      const std::size_t m = std::size_t(g.mesh);
      const auto given = mesh_default_weights_.find(m);
      if (given == mesh_default_weights_.end() || warned[m] || given->second == scene_.meshes[m].morph_weights)
        continue;
      warned[m] = true;
      warn("node " + std::to_string(i) + " has no morph weights of its own, but another node of mesh " +
           std::to_string(m) + " has: one shape per mesh, so it takes that node's weights, not the mesh's defaults");
    }
  }

  /// A node's own morph weights replace its mesh's defaults in the rest
  /// pose. One BLAS per mesh: all instances of a mesh share one shape, so
  /// the first node that gives weights wins (a differing later one is warned about).
  void node_morph_weights(std::size_t i, const tinygltf::Node& g) {
    const std::string name = "node " + std::to_string(i);
    if (g.mesh < 0) {
      warn(name + " has morph weights but no mesh; ignored");
      return;
    }
    Mesh& mesh = scene_.meshes[std::size_t(g.mesh)];
    if (mesh.morph_deltas.empty()) return;  // no targets read (or none usable): nothing to weigh
    if (g.weights.size() != mesh.morph_deltas.size())
      fail(name + " has " + std::to_string(g.weights.size()) + " morph weights for the " +
           std::to_string(mesh.morph_deltas.size()) + " morph targets of mesh " + std::to_string(g.mesh));
    std::vector<float> w(g.weights.size());
    for (std::size_t t = 0; t < w.size(); ++t) {
      if (!std::isfinite(g.weights[t])) fail(name + " has a non-finite morph weight " + std::to_string(t));
      w[t] = static_cast<float>(g.weights[t]);
    }
    if (morph_weights_set_.size() < scene_.meshes.size()) morph_weights_set_.resize(scene_.meshes.size(), false);
    if (morph_weights_set_[std::size_t(g.mesh)]) {
      if (w != mesh.morph_weights)
        warn(name + ": morph weights differ from another node's of mesh " + std::to_string(g.mesh) +
             "; the first node's are used for every instance");
      return;
    }
    morph_weights_set_[std::size_t(g.mesh)] = true;
    mesh_default_weights_[std::size_t(g.mesh)] = mesh.morph_weights;  // what a node without weights would have
    mesh.morph_weights = std::move(w);
    mesh.positions = morphed_positions(mesh, mesh.morph_weights);
  }

  /// `local` stays authoritative; TRS is filled for display when the matrix
  /// has an invertible linear part (glm::decompose divides by the scales).
  static void decompose_for_display(Node& node) {
    node.translation = glm::vec3(node.local[3]);
    if (glm::determinant(glm::mat3(node.local)) == 0.0f) return;
    glm::vec3 scale, translation, skew;
    glm::quat rotation;
    glm::vec4 perspective;
    if (glm::decompose(node.local, scale, rotation, translation, skew, perspective)) {
      node.translation = translation;
      node.rotation = rotation;
      node.scale = scale;
    }
  }

  /// The node graph must be a forest: children in range, nobody their own
  /// child, at most one parent each, no cycles. tinygltf checks none of it.
  void validate_forest() {
    const std::size_t n = scene_.nodes.size();
    for (std::size_t i = 0; i < n; ++i) {
      for (const int c : scene_.nodes[i].children) {
        if (c < 0 || std::size_t(c) >= n)
          fail("node " + std::to_string(i) + " has child " + std::to_string(c) + ", but the file has " +
               std::to_string(n) + " nodes");
        if (std::size_t(c) == i) fail("node " + std::to_string(i) + " is its own child (self-parented)");
        Node& child = scene_.nodes[std::size_t(c)];
        if (child.parent == int(i)) fail("node " + std::to_string(i) + " lists child " + std::to_string(c) + " twice");
        if (child.parent >= 0)
          fail("node " + std::to_string(c) + " has more than one parent (nodes " + std::to_string(child.parent) +
               " and " + std::to_string(i) + ")");
        child.parent = int(i);
      }
    }
    // Cycles: iterative depth-first search with three colours (white =
    // unseen, grey = on the current path, black = finished). A grey child
    // closes a cycle. Explicit stack: a 100k-node chain must not recurse.
    enum : unsigned char { white, grey, black };
    std::vector<unsigned char> colour(n, white);
    std::vector<std::pair<std::size_t, std::size_t>> stack;  // (node, next child)
    for (std::size_t start = 0; start < n; ++start) {
      if (colour[start] != white) continue;
      colour[start] = grey;
      stack.emplace_back(start, 0);
      while (!stack.empty()) {
        auto& [node, next] = stack.back();
        const std::vector<int>& children = scene_.nodes[node].children;
        if (next == children.size()) {
          colour[node] = black;
          stack.pop_back();
          continue;
        }
        const std::size_t c = std::size_t(children[next++]);
        if (colour[c] == grey) fail("node cycle: " + describe_cycle(stack, c));
        if (colour[c] == white) {
          colour[c] = grey;
          stack.emplace_back(c, 0);
        }
      }
    }
  }

  static std::string describe_cycle(const std::vector<std::pair<std::size_t, std::size_t>>& stack, std::size_t c) {
    std::size_t from = stack.size();
    while (from > 0 && stack[from - 1].first != c) --from;
    if (from > 0) --from;
    std::string s;
    const std::size_t shown = std::min<std::size_t>(stack.size() - from, 8);
    for (std::size_t k = 0; k < shown; ++k) s += std::to_string(stack[from + k].first) + " -> ";
    if (stack.size() - from > shown) s += "... -> ";
    return s + std::to_string(c);
  }

  /// The default scene's roots, else scene 0's, else every parentless node.
  std::vector<int> choose_roots() const {
    const std::size_t n = scene_.nodes.size();
    std::vector<int> roots;
    if (model_.scenes.empty()) {
      for (std::size_t i = 0; i < n; ++i)
        if (scene_.nodes[i].parent < 0) roots.push_back(int(i));
      return roots;
    }
    if (model_.defaultScene >= 0 && std::size_t(model_.defaultScene) >= model_.scenes.size())
      fail("default scene " + std::to_string(model_.defaultScene) + " does not exist (the file has " +
           std::to_string(model_.scenes.size()) + " scenes)");
    const std::size_t s = model_.defaultScene >= 0 ? std::size_t(model_.defaultScene) : 0;
    std::vector<bool> listed(n, false);
    for (const int r : model_.scenes[s].nodes) {
      const std::string where = "scene " + std::to_string(s);
      if (r < 0 || std::size_t(r) >= n)
        fail(where + " lists node " + std::to_string(r) + ", but the file has " + std::to_string(n) + " nodes");
      if (scene_.nodes[std::size_t(r)].parent >= 0)
        fail(where + " lists node " + std::to_string(r) + " as a root, but it is a child of node " +
             std::to_string(scene_.nodes[std::size_t(r)].parent));
      if (listed[std::size_t(r)]) fail(where + " lists node " + std::to_string(r) + " twice");
      listed[std::size_t(r)] = true;
      roots.push_back(r);
    }
    return roots;
  }

  /// Depth-first, pre-order, roots and children in file order: the order
  /// that numbers primitives. world = parent_world · local, composed in
  /// double (a chain of 100,000 translations drifted in float).
  void traverse(const std::vector<int>& roots) {
    std::vector<glm::dmat4> world(scene_.nodes.size(), glm::dmat4(1.0));
    std::vector<std::size_t> stack;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) {
      world[std::size_t(*it)] = glm::dmat4(local_[std::size_t(*it)]);
      stack.push_back(std::size_t(*it));
    }
    while (!stack.empty()) {
      const std::size_t i = stack.back();
      stack.pop_back();
      Node& node = scene_.nodes[i];
      const glm::mat4 m(world[i]);
      if (node.mesh >= 0) {
        Instance inst;
        inst.mesh = std::uint32_t(node.mesh);
        inst.node = std::uint32_t(i);
        inst.transform = m;
        scene_.instances.push_back(inst);
      }
      const int camera = model_.nodes[i].camera;
      if (camera >= 0) node.camera = add_camera(std::size_t(camera), i, m);
      if (node_light_[i] >= 0) node.light = add_light(std::size_t(node_light_[i]), i, m);
      for (auto c = node.children.rbegin(); c != node.children.rend(); ++c) {
        world[std::size_t(*c)] = world[i] * glm::dmat4(local_[std::size_t(*c)]);
        stack.push_back(std::size_t(*c));
      }
    }
  }

  // --- cameras and lights --------------------------------------------------

  /// glTF cameras look down their local -Z with +Y up.
  int add_camera(std::size_t index, std::size_t node, const glm::mat4& world) {
    const tinygltf::Camera& gc = model_.cameras[index];
    const std::string name = "camera " + std::to_string(index) + " (node " + std::to_string(node) + ")";
    if (gc.type != "perspective") {
      warn(name + " is " + (gc.type.empty() ? std::string("untyped") : gc.type) +
           "; skipped (only perspective cameras are supported)");
      return -1;
    }
    const double yfov = gc.perspective.yfov;
    // In float, as it is kept: 3.14159265 rounds to float's pi, a 180-degree view whose tan(yfov/2)
    // is negative.
    if (!(yfov > 0.0 && static_cast<float>(yfov) < static_cast<float>(3.14159265358979))) {
      warn(name + " has an invalid yfov " + std::to_string(yfov) + "; skipped");
      return -1;
    }
    const glm::mat3 linear(world);
    const glm::vec3 forward = linear * glm::vec3(0.0f, 0.0f, -1.0f);
    glm::vec3 up = linear * glm::vec3(0.0f, 1.0f, 0.0f);
    const float flen = glm::length(forward);
    if (!(flen > 0.0f) || !std::isfinite(flen)) {
      warn(name + " has a degenerate orientation; skipped");
      return -1;
    }
    Camera cam;
    cam.name = gc.name.empty() ? scene_.nodes[node].name : gc.name;
    cam.position = glm::vec3(world[3]);
    cam.forward = forward / flen;
    up -= glm::dot(up, cam.forward) * cam.forward;  // scale/shear can tilt it: re-orthogonalise
    const float ulen = glm::length(up);
    if (!(ulen > 0.0f) || !std::isfinite(ulen)) {
      warn(name + " has a degenerate up vector; skipped");
      return -1;
    }
    cam.up = up / ulen;
    cam.yfov = float(yfov);
    // aspectRatio is optional (0 when absent: the view's own); a negative, non-finite or absurd one
    // is said and the view's used.
    const double aspect = gc.perspective.aspectRatio;
    if (aspect != 0.0 && !(aspect >= 1e-4 && aspect <= 1e4))
      warn(name + " has an invalid aspectRatio " + std::to_string(aspect) + "; the view's own is used");
    cam.aspect = aspect >= 1e-4 && aspect <= 1e4 ? float(aspect) : 0.0f;
    scene_.cameras.push_back(cam);
    return int(scene_.cameras.size() - 1);
  }

  /// KHR_lights_punctual: lights sit at the node origin and shine down -Z.
  int add_light(std::size_t index, std::size_t node, const glm::mat4& world) {
    const tinygltf::Light& gl = model_.lights[index];
    const std::string name = "light " + std::to_string(index) + " (node " + std::to_string(node) + ")";
    Light light;
    if (gl.type == "point") {
      light.kind = Light::Kind::point;
    } else if (gl.type == "spot") {
      light.kind = Light::Kind::spot;
      const double inner = gl.spot.innerConeAngle, outer = gl.spot.outerConeAngle;
      // pi/2 as a float (what export writes back) lies a hair above pi/2 as a double: allowed.
      if (std::isfinite(inner) && std::isfinite(outer) && inner >= 0.0 && inner < outer &&
          outer <= double(float(1.5707963267948966))) {
        light.inner_cone = float(inner);
        light.outer_cone = float(outer);
      } else {
        warn(name + " has an invalid spot cone (inner " + std::to_string(inner) + ", outer " + std::to_string(outer) +
             "; glTF wants 0 <= inner < outer <= pi/2); the defaults are used");
      }
    } else if (gl.type == "directional") {
      light.kind = Light::Kind::directional;
    } else {
      warn(name + " has unknown type '" + gl.type + "'; skipped");
      return -1;
    }
    const glm::vec3 dir = glm::mat3(world) * glm::vec3(0.0f, 0.0f, -1.0f);
    const float len = glm::length(dir);
    if (light.kind != Light::Kind::point && (!(len > 0.0f) || !std::isfinite(len))) {
      warn(name + " has a degenerate direction; skipped");
      return -1;
    }
    if (len > 0.0f && std::isfinite(len)) light.direction = dir / len;
    light.name = gl.name.empty() ? scene_.nodes[node].name : gl.name;
    light.position = glm::vec3(world[3]);
    // Checked in float, as kept: a colour of 1e39 became inf, and `export` then refused the scene it
    // had loaded without a word; a negative intensity or range is not a light's.
    const auto finite_nonnegative = [](double v) { return v >= 0.0 && std::isfinite(static_cast<float>(v)); };
    if (gl.color.size() == 3) {
      if (finite_nonnegative(gl.color[0]) && finite_nonnegative(gl.color[1]) && finite_nonnegative(gl.color[2]))
        light.color = glm::vec3(gl.color[0], gl.color[1], gl.color[2]);
      else
        warn(name + " has an invalid color (negative or beyond float); white is used");
    }
    if (finite_nonnegative(gl.intensity))
      light.intensity = float(gl.intensity);
    else
      warn(name + " has an invalid intensity " + std::to_string(gl.intensity) + "; 1 is used");
    if (gl.range < 0.0 || !std::isfinite(static_cast<float>(gl.range)))
      warn(name + " has an invalid range " + std::to_string(gl.range) + "; unlimited is used");
    light.range = gl.range > 0.0 && std::isfinite(static_cast<float>(gl.range)) ? float(gl.range) : 0.0f;
    scene_.lights.push_back(light);
    return int(scene_.lights.size() - 1);
  }

  // --- animations ----------------------------------------------------------

  void convert_animations() {
    for (std::size_t a = 0; a < model_.animations.size(); ++a) {
      const tinygltf::Animation& ga = model_.animations[a];
      Animation anim;
      anim.name = ga.name;
      for (std::size_t c = 0; c < ga.channels.size(); ++c) {
        const tinygltf::AnimationChannel& gc = ga.channels[c];
        const std::string where = "animation " + std::to_string(a) + " channel " + std::to_string(c);
        if (gc.target_node < 0) {
          warn(where + " has no target node; skipped");
          continue;
        }
        if (std::size_t(gc.target_node) >= scene_.nodes.size())
          fail(where + " targets node " + std::to_string(gc.target_node) + ", but the file has " +
               std::to_string(scene_.nodes.size()) + " nodes");
        if (gc.sampler < 0 || std::size_t(gc.sampler) >= ga.samplers.size())
          fail(where + " refers to sampler " + std::to_string(gc.sampler) + ", but the animation has " +
               std::to_string(ga.samplers.size()) + " samplers");
        AnimationChannel ch;
        ch.node = gc.target_node;
        if (gc.target_path == "translation") {
          ch.path = AnimationChannel::Path::translation;
        } else if (gc.target_path == "rotation") {
          ch.path = AnimationChannel::Path::rotation;
        } else if (gc.target_path == "scale") {
          ch.path = AnimationChannel::Path::scale;
        } else if (gc.target_path == "weights") {
          ch.path = AnimationChannel::Path::weights;
        } else {
          warn(where + " has unsupported path '" + gc.target_path + "'; skipped");
          continue;
        }
        const tinygltf::AnimationSampler& gs = ga.samplers[std::size_t(gc.sampler)];
        if (gs.interpolation == "LINEAR" || gs.interpolation.empty()) {
          ch.interpolation = AnimationChannel::Interpolation::linear;
        } else if (gs.interpolation == "STEP") {
          ch.interpolation = AnimationChannel::Interpolation::step;
        } else if (gs.interpolation == "CUBICSPLINE") {
          ch.interpolation = AnimationChannel::Interpolation::cubic_spline;
        } else {
          fail(where + " has unknown interpolation '" + gs.interpolation + "'");
        }
        read_keyframes(ch, gs, where);
        if (ch.path == AnimationChannel::Path::weights) check_weights_channel(ch, where);
        anim.channels.push_back(std::move(ch));
      }
      scene_.animations.push_back(std::move(anim));
    }
    warn_animated_nodes();
  }

  /// What an animated node cannot carry along: glTF forbids animating a node given by a matrix (the
  /// animated TRS replaces it, so a shear in it is lost), and lights and cameras stay where the rest
  /// pose puts them (only instances and meshes are posed per frame). Said once per node.
  void warn_animated_nodes() {
    std::vector<bool> seen(scene_.nodes.size(), false);
    for (const Animation& a : scene_.animations)
      for (const AnimationChannel& c : a.channels) {
        if (c.path == AnimationChannel::Path::weights || c.node < 0 || seen[std::size_t(c.node)]) continue;
        seen[std::size_t(c.node)] = true;
        const std::string name = "node " + std::to_string(c.node);
        if (!model_.nodes[std::size_t(c.node)].matrix.empty())
          warn(name +
               " is animated but given by a matrix (glTF forbids it): the animated TRS replaces the matrix, "
               "so a shear in it is lost");
        // The node and its descendants: a light or a camera among them does not follow.
        std::vector<int> stack{c.node};
        std::vector<bool> visited(scene_.nodes.size(), false);
        std::string carried;
        while (!stack.empty() && carried.empty()) {
          const int n = stack.back();
          stack.pop_back();
          if (n < 0 || std::size_t(n) >= scene_.nodes.size() || visited[std::size_t(n)]) continue;
          visited[std::size_t(n)] = true;
          if (std::size_t(n) < node_light_.size() && node_light_[std::size_t(n)] >= 0)
            carried = "light " + std::to_string(node_light_[std::size_t(n)]);
          else if (model_.nodes[std::size_t(n)].camera >= 0)
            carried = "camera " + std::to_string(model_.nodes[std::size_t(n)].camera);
          for (const int child : scene_.nodes[std::size_t(n)].children) stack.push_back(child);
        }
        if (!carried.empty())
          warn(name + " is animated and carries " + carried +
               ": lights and cameras stay where the rest pose puts them (only meshes move per frame)");
      }
  }

  /// A weights channel shapes the mesh of its node: one output per morph
  /// target per key. A node without a morphing mesh makes it a no-op (warned).
  void check_weights_channel(const AnimationChannel& ch, const std::string& where) {
    const int mesh = scene_.nodes[std::size_t(ch.node)].mesh;
    if (mesh < 0 || scene_.meshes[std::size_t(mesh)].morph_deltas.empty()) {
      warn(where + " animates morph weights of node " + std::to_string(ch.node) +
           ", which has no mesh with morph targets; ignored");
      return;
    }
    const std::size_t targets = scene_.meshes[std::size_t(mesh)].morph_deltas.size();
    const std::size_t per_key = ch.interpolation == AnimationChannel::Interpolation::cubic_spline ? 3 : 1;
    if (ch.values.size() != ch.times.size() * per_key * targets)
      fail(where + ": output has " + std::to_string(ch.values.size()) + " weights for " +
           std::to_string(ch.times.size()) + " keyframes of the " + std::to_string(targets) + " morph targets of mesh " +
           std::to_string(mesh) + (per_key == 3 ? " (cubic spline: 3 per target per keyframe)" : ""));
  }

  void read_keyframes(AnimationChannel& ch, const tinygltf::AnimationSampler& gs, const std::string& where) {
    const AccessorView in = view_accessor(gs.input, "input of " + where);
    if (in.type != TINYGLTF_TYPE_SCALAR || in.component_type != TINYGLTF_COMPONENT_TYPE_FLOAT)
      fail(where + ": input accessor " + std::to_string(gs.input) + " is " + type_name(in.type) + "/" +
           component_type_name(in.component_type) + " (expected SCALAR/FLOAT)");
    if (in.count == 0) fail(where + " has no keyframes");
    ch.times.resize(in.count);
    for (std::size_t i = 0; i < in.count; ++i) {
      ch.times[i] = read_normalized(in, i, 0);
      // A NaN or infinite time would make every sample of the channel NaN
      // (and the instance's transform with it), far from here.
      if (!std::isfinite(ch.times[i]))
        fail(where + ": keyframe " + std::to_string(i) + " has time " + std::to_string(ch.times[i]) +
             " (times must be finite)");
    }
    if (!std::is_sorted(ch.times.begin(), ch.times.end()))
      warn(where + ": keyframe times are not increasing");

    const AccessorView out = view_accessor(gs.output, "output of " + where);
    const bool rotation = ch.path == AnimationChannel::Path::rotation;
    const bool weights = ch.path == AnimationChannel::Path::weights;
    const int expected_type = rotation ? TINYGLTF_TYPE_VEC4 : weights ? TINYGLTF_TYPE_SCALAR : TINYGLTF_TYPE_VEC3;
    // Rotations and weights may be normalised integers (glTF 2.0 §5.5.x);
    // translations and scales are always float.
    const int ct = out.component_type;
    const bool float_ok = ct == TINYGLTF_COMPONENT_TYPE_FLOAT;
    const bool int_ok = (rotation || weights) && out.normalized &&
                        (ct == TINYGLTF_COMPONENT_TYPE_BYTE || ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                         ct == TINYGLTF_COMPONENT_TYPE_SHORT || ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
    if (out.type != expected_type || !(float_ok || int_ok))
      fail(where + ": output accessor " + std::to_string(gs.output) + " is " + type_name(out.type) + "/" +
           component_type_name(ct) + (out.normalized ? " normalized" : "") + " (expected " + type_name(expected_type) +
           (rotation || weights ? "/FLOAT or normalized integers)" : "/FLOAT)"));
    const std::size_t per_key = ch.interpolation == AnimationChannel::Interpolation::cubic_spline ? 3 : 1;
    // Weights hold one value per morph target per key: any positive multiple.
    const bool count_ok = weights ? out.count % (in.count * per_key) == 0 && out.count > 0
                                  : out.count == in.count * per_key;
    if (!count_ok)
      fail(where + ": output has " + std::to_string(out.count) + " values for " + std::to_string(in.count) +
           " keyframes" + (per_key == 3 ? " (cubic spline needs 3 per keyframe)" : ""));
    const std::size_t ncomp = component_count(out.type);
    ch.values.resize(out.count, glm::vec4(0.0f));
    for (std::size_t i = 0; i < out.count; ++i)
      for (std::size_t k = 0; k < ncomp; ++k) {
        ch.values[i][int(k)] = read_normalized(out, i, k);
        if (!std::isfinite(ch.values[i][int(k)]))
          fail(where + ": output value " + std::to_string(i) + " (keyframe " +
               std::to_string(i / (out.count / in.count)) + ") is not finite");
      }
  }

  // --- checks --------------------------------------------------------------

  void warn_ignored_extensions() {
    for (const std::string& ext : model_.extensionsUsed)
      if (ext == "EXT_mesh_gpu_instancing" || ext == "KHR_draco_mesh_compression" || ext == "EXT_meshopt_compression")
        warn("extension " + ext + " is used but not supported; its data is ignored");
  }

  /// A file can produce a warning per node or primitive (100k skinned
  /// nodes); keep the first few and say how many more there were.
  void cap_warnings() {
    constexpr std::size_t kMaxWarnings = 100;
    std::vector<std::string>& w = scene_.report.warnings;
    if (w.size() <= kMaxWarnings) return;
    const std::size_t more = w.size() - kMaxWarnings;
    w.resize(kMaxWarnings);
    w.push_back("... and " + std::to_string(more) + " more warnings");
  }

  /// Before any mesh is read: the triangles the primitives would unroll to,
  /// from their accessors' counts. One accessor used by many primitives would
  /// otherwise be copied that many times (a 12 MB file took 3 GB and more).
  void check_mesh_triangle_count() const {
    std::uint64_t total = 0;
    for (const tinygltf::Mesh& gm : model_.meshes)
      for (const tinygltf::Primitive& prim : gm.primitives) {
        const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
        if (mode < TINYGLTF_MODE_TRIANGLES || mode > TINYGLTF_MODE_TRIANGLE_FAN) continue;
        int accessor = prim.indices;
        if (accessor < 0) {
          const auto pos = prim.attributes.find("POSITION");
          if (pos == prim.attributes.end()) continue;
          accessor = pos->second;
        }
        if (accessor < 0 || static_cast<std::size_t>(accessor) >= model_.accessors.size()) continue;  // named later
        const std::uint64_t n = model_.accessors[static_cast<std::size_t>(accessor)].count;
        total += mode == TINYGLTF_MODE_TRIANGLES ? n / 3 : (n >= 3 ? n - 2 : 0);
      }
    if (total > kMaxWorldTriangles)
      fail("the meshes' primitives declare " + std::to_string(total) +
           " triangles (their accessors' counts), more than the limit of " + std::to_string(kMaxWorldTriangles));
  }

  void check_world_triangle_count() const {
    const std::uint64_t total = scene_.instanced_triangle_count();
    if (total > kMaxWorldTriangles)
      fail("instances expand to " + std::to_string(total) + " world triangles, more than the limit of " +
           std::to_string(kMaxWorldTriangles));
  }

  const std::string& path_;
  const tinygltf::Model& model_;
  Scene& scene_;
  std::vector<glm::mat4> local_;
  std::vector<int> node_light_;
  std::vector<bool> morph_weights_set_;  ///< per mesh: a node's weights became its rest pose
  std::map<std::size_t, std::vector<float>> mesh_default_weights_;  ///< those meshes' own default weights
};

// --- Step 1: reading the file ----------------------------------------------

[[noreturn]] void fail_file(const std::string& path, const std::string& problem) {
  throw SceneError(path + ": " + first_line(problem));
}

std::vector<unsigned char> read_file(const std::string& path) {
  std::uintmax_t size = 0;
  if (const std::string problem = input_file_problem(path, kMaxFileBytes, size, kTooLarge); !problem.empty())
    fail_file(path, problem);
  std::ifstream in(path, std::ios::binary);
  if (!in) fail_file(path, "cannot open for reading");
  std::vector<unsigned char> data(static_cast<std::size_t>(size));
  if (size > 0 && !in.read(reinterpret_cast<char*>(data.data()), std::streamsize(size)))
    fail_file(path, "read error");
  return data;
}

struct GlbLayout {
  std::size_t json_offset = 0, json_length = 0;
  std::size_t total_length = 0;  ///< what tinygltf gets: the header's length
};

/// GLB container (glTF 2.0 §4.4): 12-byte header, then chunks of
/// (length, type, payload). Every length is checked against the real file
/// size before tinygltf, which trusts them, sees the bytes.
GlbLayout check_glb(const std::string& path, const std::vector<unsigned char>& data) {
  const std::size_t size = data.size();
  if (size < 12) fail_file(path, "truncated GLB: " + std::to_string(size) + " bytes, the header alone needs 12");
  const std::uint32_t magic = read_u32_le(&data[0]);
  if (magic != kGlbMagic)
    fail_file(path, "not a binary glTF file: wrong magic " + hex32(magic) + " (expected 'glTF')");
  const std::uint32_t version = read_u32_le(&data[4]);
  if (version != 2) fail_file(path, "unsupported GLB version " + std::to_string(version) + " (expected 2)");
  const std::uint32_t length = read_u32_le(&data[8]);
  if (length > size)
    fail_file(path, "truncated GLB: header says " + std::to_string(length) + " bytes, file has " + std::to_string(size));
  if (length < 20) fail_file(path, "malformed GLB: header length " + std::to_string(length) + " leaves no room for a JSON chunk");

  GlbLayout layout;
  layout.total_length = length;
  std::size_t offset = 12;
  int chunk = 0;
  while (offset < length) {
    if (length - offset < 8)
      fail_file(path, "truncated GLB: chunk " + std::to_string(chunk) + " header at byte " + std::to_string(offset) +
                          " runs past the end (" + std::to_string(length) + " bytes)");
    const std::uint32_t chunk_length = read_u32_le(&data[offset]);
    const std::uint32_t chunk_type = read_u32_le(&data[offset + 4]);
    if (chunk_length > length - offset - 8)
      fail_file(path, "malformed GLB: chunk " + std::to_string(chunk) + " length " + std::to_string(chunk_length) +
                          " is larger than the " + std::to_string(length - offset - 8) + " bytes left in the file");
    if (chunk == 0) {
      if (chunk_type != kGlbChunkJson)
        fail_file(path, "malformed GLB: first chunk has type " + hex32(chunk_type) + " (expected JSON)");
      // Said here: the bytes after an empty JSON chunk would be read as the next chunk's header.
      if (chunk_length == 0) fail_file(path, "malformed GLB: empty JSON chunk");
      layout.json_offset = offset + 8;
      layout.json_length = chunk_length;
    } else if (chunk == 1 && chunk_type != kGlbChunkBin) {
      // tinygltf reads the second chunk as BIN unconditionally.
      fail_file(path, "malformed GLB: second chunk has type " + hex32(chunk_type) + " (expected BIN)");
    }
    offset += 8 + std::size_t(chunk_length);
    ++chunk;
  }
  if (layout.json_length == 0) fail_file(path, "malformed GLB: empty JSON chunk");
  return layout;
}

std::vector<std::string> precheck_json(const std::string& path, const unsigned char* text, std::size_t length) {
  JsonPrecheck sax;
  const char* begin = reinterpret_cast<const char*>(text);
  // The parser stops at a NUL byte as at the end: what follows one was never read (junk after it was
  // accepted, though junk after the JSON itself is an error). NUL padding at the end is let be.
  if (const void* nul = std::memchr(begin, '\0', length)) {
    const std::size_t at = static_cast<std::size_t>(static_cast<const char*>(nul) - begin);
    for (std::size_t i = at; i < length; ++i)
      if (begin[i] != '\0' && begin[i] != ' ' && begin[i] != '\n' && begin[i] != '\r' && begin[i] != '\t')
        fail_file(path, "malformed JSON: a NUL byte at offset " + std::to_string(at) + " with more after it");
  }
  nlohmann::json::sax_parse(begin, begin + length, &sax);
  if (!sax.error.empty()) fail_file(path, sax.error);
  for (const std::string& ext : sax.required)
    if (!required_extension_supported(ext))
      fail_file(path, "requires extension '" + ext + "', which is not supported");
  return sax.warnings;
}

/// We trace geometry only; decoding textures would cost time and add failure
/// modes (missing or corrupt images) that cannot change a single triangle.
bool skip_image(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int, void*) {
  return true;
}

/// tinygltf's messages, made one line and, for the common missing external
/// buffer, rephrased to name the file plainly.
std::string tinygltf_problem(const std::string& err) {
  const std::string line = first_line(err);
  const std::string not_found = "File not found : ";
  if (line.rfind(not_found, 0) == 0) {
    const std::string uri = line.substr(not_found.size());
    // A URI tinygltf does not read falls through to a file lookup: say what it is instead.
    if (uri.rfind("data:", 0) == 0)
      return "invalid glTF: a buffer's data URI is not one that can be read (base64, media type "
             "application/octet-stream or application/gltf-buffer)";
    if (const auto colon = uri.find("://"); colon != std::string::npos && colon < 10)
      return "invalid glTF: a buffer's URI scheme '" + uri.substr(0, colon) +
             "' is not supported (a file path relative to the glTF, or a base64 data URI)";
    return "external buffer file '" + uri + "' not found";
  }
  // tinygltf says "must be the multiple of 4" of any value out of range, 300 included.
  if (line.rfind("Invalid `byteStride' value.", 0) == 0 || line.rfind("Invalid 'byteStride' value.", 0) == 0) {
    const auto colon = line.rfind(": ");
    return "invalid glTF: a bufferView's byteStride " +
           (colon == std::string::npos ? "" : line.substr(colon + 2) + " ") + "is not a multiple of 4 from 4 to 252";
  }
  if (line == "JSON string too short.")
    return "invalid glTF: the JSON is empty or too short (a glTF needs at least \"asset\": {\"version\": \"2.0\"})";
  // Its message would quote the whole data URI.
  if (line.rfind("Failed to decode 'uri' : data:", 0) == 0)
    return "invalid glTF: a buffer's data URI cannot be decoded or its size differs from byteLength";
  return "invalid glTF: " + line;
}

// tinygltf's file access for the files a .gltf or .glb names (buffers,
// images): its own FileExists opens the file and ReadWholeFile reads what
// ifstream gives, so a FIFO blocked and a directory asked for an allocation
// of SIZE_MAX. Only regular files of at most kMaxFileBytes are read.
bool external_file_exists(const std::string& path, void*) {
  std::error_code ec;
  return fs::exists(fs::status(path, ec));
}

bool read_external_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void*) {
  const auto problem = [&](const std::string& what) {  // tinygltf adds "File read error : PATH : "
    if (err) *err += what;
    return false;
  };
  // A URI's %00 (or a malformed escape, which tinygltf decodes to 0) puts a
  // NUL in the name: the file system would read only what comes before it.
  if (path.find('\0') != std::string::npos)
    return problem("its name holds a NUL byte (a %00 or malformed escape in the URI)");
  std::uintmax_t size = 0;
  if (const std::string p = input_file_problem(path, kMaxFileBytes, size, kTooLarge); !p.empty()) return problem(p);
  if (size == 0) return problem("empty file");
  std::ifstream in(path, std::ios::binary);
  if (!in) return problem("cannot open for reading");
  out->resize(static_cast<std::size_t>(size));
  in.read(reinterpret_cast<char*>(out->data()), static_cast<std::streamsize>(size));
  if (in.gcount() != static_cast<std::streamsize>(size)) return problem("read error");
  return true;
}

}  // namespace

Scene load_gltf(const std::string& path) {
  const std::vector<unsigned char> data = read_file(path);
  const bool binary = data.size() >= 4 && read_u32_le(data.data()) == kGlbMagic;
  const std::string ext = lower_extension(path);

  tinygltf::Model model;
  tinygltf::TinyGLTF gltf;
  gltf.SetImageLoader(&skip_image, nullptr);
  gltf.SetFsCallbacks(
      {&external_file_exists, &tinygltf::ExpandFilePath, &read_external_file, &tinygltf::WriteWholeFile, nullptr});
  std::string err, warn;
  std::vector<std::string> json_warnings;
  const std::string base_dir = fs::path(path).parent_path().string();
  bool ok = false;
  if (binary || ext == ".glb") {
    const GlbLayout layout = check_glb(path, data);
    json_warnings = precheck_json(path, data.data() + layout.json_offset, layout.json_length);
    ok = gltf.LoadBinaryFromMemory(&model, &err, &warn, data.data(), unsigned(layout.total_length), base_dir);
  } else {
    if (data.empty()) fail_file(path, "empty file");
    json_warnings = precheck_json(path, data.data(), data.size());
    ok = gltf.LoadASCIIFromString(&model, &err, &warn, reinterpret_cast<const char*>(data.data()), unsigned(data.size()),
                                  base_dir);
  }
  if (!ok) fail_file(path, tinygltf_problem(err));

  Scene scene;
  scene.source = path;
  scene.report.warnings = json_warnings;
  // tinygltf says an unreadable image in two lines, its file's problem and "Failed to load external
  // 'uri' for image[N] name = []": one warning in our words.
  std::vector<std::string> notes = lines_of(warn);
  for (const std::string& line : lines_of(err)) notes.push_back(line);  // non-fatal notes
  for (std::size_t i = 0; i < notes.size(); ++i) {
    const std::string& line = notes[i];
    constexpr std::string_view kFailed = "Failed to load external 'uri' for image[";
    if (line.starts_with(kFailed) && !scene.report.warnings.empty() && i > 0 &&
        scene.report.warnings.back() == notes[i - 1]) {
      const std::string image = line.substr(kFailed.size(), line.find(']') - kFailed.size());
      std::string what = notes[i - 1];
      for (const std::string_view prefix : {"File not found : ", "File read error : "})
        if (what.starts_with(prefix)) what = what.substr(prefix.size());
      if (notes[i - 1].starts_with("File not found : ")) what = "'" + what + "' not found";
      if (const std::size_t sep = what.find(" : "); sep != std::string::npos) what.replace(sep, 3, ": ");
      scene.report.warnings.back() =
          "image " + image + ": " + what + " (images are never decoded: no traced triangle changes)";
      continue;
    }
    scene.report.warnings.push_back(line);
  }
  GltfConverter(path, model, scene).run();
  return scene;
}

}  // namespace accelviz
