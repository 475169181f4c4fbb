// Wavefront OBJ loading through tinyobjloader, with the validation it lacks.
//
// tinyobjloader (Debian 2.0.0rc10) is forgiving in ways that would corrupt
// a measurement silently: an unparsable coordinate becomes 0, "nan"/"inf"
// become 0, a face with an out-of-range index is skipped with a warning, and
// polygons go through an ear-clipper that may emit fewer than n-2 triangles.
// So the steps are:
//   1. our own line scan: every `v` line has numeric coordinates, every
//      `f` line has at least three well-formed vertex references that
//      resolve to existing vertices (negative = relative, OBJ style);
//      `l`/`p` elements are counted as skipped primitives;
//   2. tinyobjloader parses the same bytes into shapes (one per o/g group;
//      `usemtl` does not split one) without triangulating (a face of more
//      than 255 vertices first rewritten as the triangles of its whole
//      outline: split_long_faces); a missing .mtl,
//      or one that is not a regular file of at most 64 MiB, is only a
//      warning;
//   3. each shape becomes one Mesh with its own compacted vertices and an
//      identity instance; convex quads are cut along v0-v2, larger convex
//      polygons split in halves, concave ones ear-clipped
//      (core/geometry/polygon.h), so a polygon of n
//      vertices always gives n-2 triangles, in file order;
//   4. coordinates our scan read as NaN/inf are restored, so flatten() drops
//      those triangles and counts them instead of placing them at the origin.
#include <tiny_obj_loader.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <span>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "core/geometry/polygon.h"
#include "core/scene/load.h"
#include "core/util/file_checks.h"
#include "core/util/one_line.h"

namespace accelviz {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void obj_fail(const std::string& path, const std::string& problem) {
  throw SceneError(path + ": " + first_line(problem));
}

/// A token as it appears in a message: cut short, control bytes shown as '?'.
std::string quoted(std::string_view token) {
  constexpr std::size_t kMaxToken = 40;
  std::string s(token.substr(0, kMaxToken));
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F) c = '?';
  if (token.size() > kMaxToken) s += "...";
  return "'" + s + "'";
}

/// Splits on spaces and tabs (tinyobjloader's separators).
std::vector<std::string_view> tokens_of(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

/// An OBJ coordinate: decimal with optional exponent, or nan/inf/infinity
/// (any case, signed). Hex floats and trailing junk are rejected because
/// tinyobjloader would read them as something else.
bool parse_coordinate(std::string_view token, double& value) {
  std::string s(token);
  std::string lower = s;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  std::string_view body = lower;
  if (!body.empty() && (body[0] == '+' || body[0] == '-')) body.remove_prefix(1);
  if (body == "nan" || body == "inf" || body == "infinity") {
    value = body == "nan" ? std::numeric_limits<double>::quiet_NaN() : std::numeric_limits<double>::infinity();
    if (lower[0] == '-') value = -value;
    return true;
  }
  bool digits = false;
  for (const char c : body) {
    if (c >= '0' && c <= '9') {
      digits = true;
    } else if (c != '.' && c != 'e' && c != '+' && c != '-') {
      return false;
    }
  }
  if (!digits) return false;
  errno = 0;
  char* end = nullptr;
  value = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size();  // ERANGE overflow gives ±inf: kept, dropped later
}

/// A signed decimal integer that fits in long long; false otherwise.
bool parse_integer(std::string_view token, long long& value) {
  if (token.empty()) return false;
  std::size_t i = (token[0] == '+' || token[0] == '-') ? 1 : 0;
  if (i == token.size()) return false;
  for (std::size_t k = i; k < token.size(); ++k)
    if (token[k] < '0' || token[k] > '9') return false;
  if (token.size() - i > 18) return false;  // beyond any real vertex count; avoids overflow
  value = std::strtoll(std::string(token).c_str(), nullptr, 10);
  return true;
}

/// Calls f(line, number) for every line of `text` (numbered from 1): lines
/// end in \n, \r\n or a lone \r, as tinyobjloader reads them.
template <class F>
void for_each_line(const std::string& text, const F& f) {
  std::size_t line_number = 0, pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find_first_of("\r\n", pos);
    if (end == std::string::npos) end = text.size();
    const std::string_view line(text.data() + pos, end - pos);
    pos = end + (text.compare(end, 2, "\r\n") == 0 ? 2 : 1);
    f(line, ++line_number);
  }
}

/// tinyobjloader keeps a face's vertex count in an unsigned char: a face of
/// more vertices comes back with its count modulo 256, and the faces after
/// it are misread (silently wrong triangles).
constexpr std::size_t kMaxTinyObjFace = 255;

/// `text` with every face of more than kMaxTinyObjFace vertices written as
/// the triangles triangulate_polygon makes of its whole outline (convex:
/// halves; concave: ear-clipped), one `f a b c` line each, at the face's
/// place (its group and material stay). Other lines are kept as they are;
/// relative (negative) indices stay valid, as no vertex line moves. The
/// coordinates come from a first pass over the `v` lines (positive indices
/// may refer forward); scan_obj has checked every line already.
std::string split_long_faces(const std::string& text) {
  std::vector<glm::vec3> positions;
  for_each_line(text, [&](std::string_view line, std::size_t) {
    const std::vector<std::string_view> tok = tokens_of(line);
    if (tok.size() < 4 || tok[0] != "v") return;
    double xyz[3] = {0, 0, 0};
    for (int k = 0; k < 3; ++k) parse_coordinate(tok[1 + k], xyz[k]);
    positions.emplace_back(float(xyz[0]), float(xyz[1]), float(xyz[2]));
  });
  std::string out;
  out.reserve(text.size() + text.size() / 8);
  std::size_t vertices_so_far = 0;
  std::vector<glm::vec3> corners;
  for_each_line(text, [&](std::string_view line, std::size_t) {
    const std::vector<std::string_view> tok = tokens_of(line);
    if (!tok.empty() && tok[0] == "v" && tok.size() >= 4) ++vertices_so_far;
    if (tok.empty() || tok[0] != "f" || tok.size() - 1 <= kMaxTinyObjFace) {
      out.append(line);
      out += '\n';
      return;
    }
    const std::span<const std::string_view> refs = std::span<const std::string_view>(tok).subspan(1);
    corners.clear();
    for (const std::string_view ref : refs) {
      long long v = 0;
      parse_integer(ref.substr(0, ref.find('/')), v);
      const long long index = v < 0 ? static_cast<long long>(vertices_so_far) + v : v - 1;
      corners.push_back(positions[static_cast<std::size_t>(index)]);
    }
    for (const auto& t : triangulate_polygon(corners)) {
      out += 'f';
      for (const std::uint32_t c : t) {
        out += ' ';
        out.append(refs[c]);
      }
      out += '\n';
    }
  });
  return out;
}

struct ObjScan {
  std::size_t vertex_count = 0;
  std::size_t face_count = 0;
  std::size_t long_faces = 0;  ///< faces of more than kMaxTinyObjFace vertices (split_long_faces)
  std::uint64_t lines_and_points = 0;
  /// Lines whose statement OBJ does not have (a typo such as `F 1 2 3` or `fo 1 2 3`: tinyobjloader
  /// drops them without a word) and free-form geometry (`curv`, `curv2`, `surf`: not read); the
  /// first of each as "line N 'KEYWORD'".
  std::uint64_t unknown_statements = 0, free_form = 0;
  std::string first_unknown, first_free_form;
  /// (vertex index, xyz as read) for every vertex with a NaN/inf coordinate.
  std::vector<std::pair<std::size_t, glm::vec3>> nonfinite;
};

/// Step 1: validates `v` and `f` lines; reports the first problem with its
/// line number. Positive indices may refer forward (tinyobjloader allows it),
/// so they are checked against the final vertex count.
ObjScan scan_obj(const std::string& path, const std::string& text) {
  ObjScan scan;
  long long max_forward = 0;
  std::size_t max_forward_line = 0;
  for_each_line(text, [&](std::string_view line, std::size_t line_number) {
    const std::vector<std::string_view> tok = tokens_of(line);
    if (tok.empty() || tok[0][0] == '#') return;
    const std::string where = "line " + std::to_string(line_number) + ": ";

    if (tok[0] == "v") {
      if (tok.size() < 4)
        obj_fail(path, where + "vertex has " + std::to_string(tok.size() - 1) + " coordinates (expected at least 3)");
      double xyz[3] = {0, 0, 0};
      for (std::size_t k = 1; k < tok.size(); ++k) {
        double value = 0;
        if (!parse_coordinate(tok[k], value))
          obj_fail(path, where + "vertex coordinate " + quoted(tok[k]) + " is not a number" +
                             (tok[k].starts_with('#') ? " (a comment starts its own line)" : ""));
        if (k <= 3) xyz[k - 1] = value;
      }
      if (!std::isfinite(xyz[0]) || !std::isfinite(xyz[1]) || !std::isfinite(xyz[2]))
        scan.nonfinite.emplace_back(scan.vertex_count, glm::vec3(float(xyz[0]), float(xyz[1]), float(xyz[2])));
      ++scan.vertex_count;
      if (scan.vertex_count > std::size_t(INT_MAX)) obj_fail(path, where + "more than 2^31 vertices");
      return;
    }

    const bool face = tok[0] == "f";
    if (face || tok[0] == "l" || tok[0] == "p") {
      const std::size_t refs = tok.size() - 1;
      if (face && refs < 3)
        obj_fail(path, where + "face has " + std::to_string(refs) + " vertices (expected at least 3)");
      if (!face && refs < 1) obj_fail(path, where + "'" + std::string(tok[0]) + "' element has no vertices");
      for (std::size_t k = 1; k < tok.size(); ++k) {
        // v, v/vt, v//vn or v/vt/vn; only v is used, but all must be integers.
        const std::string_view ref = tok[k];
        std::string_view parts[3];
        std::size_t count = 0, start = 0;
        for (std::size_t i = 0; i <= ref.size(); ++i) {
          if (i == ref.size() || ref[i] == '/') {
            if (count == 3) obj_fail(path, where + "malformed vertex reference " + quoted(ref));
            parts[count++] = ref.substr(start, i - start);
            start = i + 1;
          }
        }
        long long v = 0, other = 0;
        if (!parse_integer(parts[0], v))
          obj_fail(path, where + "malformed vertex reference " + quoted(ref) +
                             (ref.starts_with('#') ? " (a comment starts its own line)" : ""));
        // Only the texture slot of v//vn may be empty; "v/" and "v/vt/" are malformed.
        for (std::size_t p = 1; p < count; ++p) {
          if (parts[p].empty() && p == 1 && count == 3) continue;
          if (!parse_integer(parts[p], other)) obj_fail(path, where + "malformed vertex reference " + quoted(ref));
          if (other == 0)
            obj_fail(path, where + "texture/normal index 0 in " + quoted(ref) + " is invalid (OBJ indices start at 1)");
        }
        if (v == 0) obj_fail(path, where + "vertex index 0 is invalid (OBJ indices start at 1)");
        if (v < 0 && -v > static_cast<long long>(scan.vertex_count))
          obj_fail(path, where + "relative vertex index " + std::to_string(v) + " is out of range (only " +
                             std::to_string(scan.vertex_count) + " vertices so far)");
        if (v > max_forward) {
          max_forward = v;
          max_forward_line = line_number;
        }
      }
      if (face) {
        ++scan.face_count;
        if (refs > kMaxTinyObjFace) ++scan.long_faces;
      } else {
        ++scan.lines_and_points;
      }
      return;
    }
    // The statements of the OBJ specification (Wavefront, version 3.0) that are not read above.
    static constexpr std::string_view kKnown[] = {
        "vt",        "vn",     "vp",     "o",      "g",     "s",        "mg",       "mtllib",
        "usemtl",    "maplib", "usemap", "lod",    "bevel", "c_interp", "d_interp", "shadow_obj",
        "trace_obj", "ctech",  "stech",  "cstype", "deg",   "bmat",     "step",     "parm",
        "trim",      "hole",   "scrv",   "sp",     "end",   "con",      "call",     "csh"};
    if (tok[0] == "curv" || tok[0] == "curv2" || tok[0] == "surf") {
      if (scan.free_form++ == 0) scan.first_free_form = "line " + std::to_string(line_number) + " " + quoted(tok[0]);
    } else if (std::find(std::begin(kKnown), std::end(kKnown), tok[0]) == std::end(kKnown)) {
      if (scan.unknown_statements++ == 0)
        scan.first_unknown = "line " + std::to_string(line_number) + " " + quoted(tok[0]);
    }
  });
  if (max_forward > static_cast<long long>(scan.vertex_count))
    obj_fail(path, "line " + std::to_string(max_forward_line) + ": vertex index " + std::to_string(max_forward) +
                       " is out of range (the file has " + std::to_string(scan.vertex_count) + " vertices)");
  return scan;
}

std::string read_text(const std::string& path) {
  std::uintmax_t size = 0;
  if (const std::string problem = input_file_problem(path, std::numeric_limits<std::uintmax_t>::max(), size);
      !problem.empty())
    obj_fail(path, problem);
  std::ifstream in(path, std::ios::binary);
  if (!in) obj_fail(path, "cannot open for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) obj_fail(path, "read error");
  return std::move(ss).str();
}

/// A file can produce a warning per line (say, a missing material on every
/// `usemtl`); keep the first few and say how many more there were.
void cap_warnings(LoadReport& report) {
  constexpr std::size_t kMaxWarnings = 100;
  if (report.warnings.size() <= kMaxWarnings) return;
  const std::size_t more = report.warnings.size() - kMaxWarnings;
  report.warnings.resize(kMaxWarnings);
  report.warnings.push_back("... and " + std::to_string(more) + " more warnings");
}

std::vector<std::string> warning_lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line))
    if (line.find_first_not_of(" \t\r.") != std::string::npos) out.push_back(first_line(line));
  return out;
}

/// tinyobjloader's MaterialFileReader opens the `mtllib` file with ifstream
/// and reads it line by line: a FIFO blocked, /dev/zero grew a line without
/// bound. Here only a regular file of at most 64 MiB is read (the materials
/// are not used: no view draws them); anything else is a warning, as a
/// missing .mtl is.
class BoundedMaterialReader : public tinyobj::MaterialReader {
 public:
  explicit BoundedMaterialReader(std::string dir) : dir_(std::move(dir)) {}
  bool operator()(const std::string& name, std::vector<tinyobj::material_t>* materials,
                  std::map<std::string, int>* names, std::string* warn, std::string* err) override {
    constexpr std::uintmax_t kMaxMtlBytes = std::uintmax_t{64} << 20;
    const std::string path = dir_ + name;
    const auto skip = [&](const std::string& why) {
      if (warn) *warn += "Material file [ " + name + " ] " + why + "\n";
      return false;
    };
    std::uintmax_t size = 0;
    if (const std::string problem = input_file_problem(path, kMaxMtlBytes, size); !problem.empty())
      return skip(problem == "no such file" ? "not found." : problem + "; materials skipped.");
    std::ifstream in(path, std::ios::binary);
    if (!in) return skip("cannot be opened.");
    tinyobj::LoadMtl(names, materials, &in, warn, err);
    return true;
  }

 private:
  std::string dir_;
};

}  // namespace

Scene load_obj(const std::string& path) {
  std::string text = read_text(path);
  // A UTF-8 byte order mark is not part of the first line.
  if (text.starts_with("\xEF\xBB\xBF")) text.erase(0, 3);
  const ObjScan scan = scan_obj(path, text);
  if (scan.long_faces > 0) text = split_long_faces(text);

  // Step 2: tinyobjloader over the same bytes. Materials are resolved next to
  // the .obj; a missing .mtl only adds a warning.
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn, err;
  std::istringstream stream(text);
  std::string base_dir = fs::path(path).parent_path().string();
  if (base_dir.empty()) base_dir = ".";
  BoundedMaterialReader material_reader(base_dir + "/");
  const bool ok = tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &stream, &material_reader,
                                   /*triangulate=*/false, /*default_vcols_fallback=*/false);
  if (!ok) obj_fail(path, err.empty() ? "tinyobjloader failed" : err);

  Scene scene;
  scene.source = path;
  for (const std::string& line : warning_lines(warn)) scene.report.warnings.push_back(line);
  for (const std::string& line : warning_lines(err)) scene.report.warnings.push_back(line);
  if (scan.lines_and_points > 0) {
    scene.report.skipped_primitives = scan.lines_and_points;
    scene.report.warnings.push_back(std::to_string(scan.lines_and_points) +
                                    " line/point elements skipped (only faces are traced)");
  }
  if (scan.unknown_statements > 0)
    scene.report.warnings.push_back(count_of(scan.unknown_statements, "line") +
                                    " ignored: a statement OBJ does not have (first: " + scan.first_unknown + ")");
  if (scan.free_form > 0)
    scene.report.warnings.push_back("free-form curves and surfaces not read (only polygonal faces are): " +
                                    std::to_string(scan.free_form) + " (first: " + scan.first_free_form + ")");

  std::vector<float>& v = attrib.vertices;
  if (v.size() != scan.vertex_count * 3)
    obj_fail(path, "tinyobjloader read " + std::to_string(v.size() / 3) + " vertices, the file has " +
                       std::to_string(scan.vertex_count));
  // Step 4 (early, so that the meshes copy the right values).
  for (const auto& [index, xyz] : scan.nonfinite) {
    v[3 * index + 0] = xyz.x;
    v[3 * index + 1] = xyz.y;
    v[3 * index + 2] = xyz.z;
  }

  // Step 3: one Mesh per shape, vertices compacted. `slot` maps a global
  // vertex to its index in the current mesh; `owner` says which mesh set it,
  // so that the map never needs clearing between shapes.
  const std::size_t nv = scan.vertex_count;
  std::vector<std::uint32_t> slot(nv, 0);
  std::vector<std::uint32_t> owner(nv, std::numeric_limits<std::uint32_t>::max());
  for (const tinyobj::shape_t& shape : shapes) {
    const tinyobj::mesh_t& sm = shape.mesh;
    if (sm.num_face_vertices.empty()) continue;
    const auto mesh_id = std::uint32_t(scene.meshes.size());
    Mesh mesh;
    mesh.name = shape.name;
    auto local = [&](const tinyobj::index_t& idx) -> std::uint32_t {
      const int g = idx.vertex_index;
      if (g < 0 || std::size_t(g) >= nv)  // the scan makes this unreachable; never index out of bounds
        obj_fail(path, "vertex index " + std::to_string(g + 1) + " is out of range in shape '" + shape.name + "'");
      if (owner[std::size_t(g)] != mesh_id) {
        owner[std::size_t(g)] = mesh_id;
        slot[std::size_t(g)] = std::uint32_t(mesh.positions.size());
        mesh.positions.emplace_back(v[3 * std::size_t(g)], v[3 * std::size_t(g) + 1], v[3 * std::size_t(g) + 2]);
      }
      return slot[std::size_t(g)];
    };
    std::size_t offset = 0;
    std::vector<std::uint32_t> face_ids;
    std::vector<glm::vec3> face_corners;
    for (const unsigned int n : sm.num_face_vertices) {
      if (offset + n > sm.indices.size()) obj_fail(path, "tinyobjloader returned inconsistent face data");
      if (n >= 3) {
        // Convex faces split, concave ones ear-clipped (core/geometry/polygon.h).
        face_ids.clear();
        face_corners.clear();
        for (unsigned int k = 0; k < n; ++k) {
          face_ids.push_back(local(sm.indices[offset + k]));
          face_corners.push_back(mesh.positions[face_ids.back()]);
        }
        for (const auto& [a, b, c] : triangulate_polygon(face_corners))
          mesh.indices.emplace_back(face_ids[a], face_ids[b], face_ids[c]);
      }
      offset += n;
    }
    Node node;
    node.name = shape.name;
    node.mesh = int(mesh_id);
    scene.roots.push_back(int(scene.nodes.size()));
    Instance inst;
    inst.mesh = mesh_id;
    inst.node = std::uint32_t(scene.nodes.size());
    scene.nodes.push_back(node);
    scene.instances.push_back(inst);
    scene.meshes.push_back(std::move(mesh));
  }

  scene.flatten();
  if (scene.triangles.empty()) {
    // The statements it ignored may be why (`F 1 2 3` on every face line).
    std::string also;
    for (const std::string& w : scene.report.warnings)
      if (w.find("a statement OBJ does not have") != std::string::npos || w.starts_with("free-form")) also += "; " + w;
    obj_fail(path, no_triangles_message(scene.report) + also);
  }
  cap_warnings(scene.report);
  return scene;
}

}  // namespace accelviz
