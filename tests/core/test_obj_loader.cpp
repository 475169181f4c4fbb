// load_obj: every fixture is written by the test into its own temp directory.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/scene/load.h"
#include "tests/support/temp_dir.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_obj_loader {

using namespace accelviz;
namespace fs = std::filesystem;

namespace {

void expect_vec3_near(const glm::vec3& a, const glm::vec3& b, float eps = 1e-6f) {
  EXPECT_NEAR(a.x, b.x, eps);
  EXPECT_NEAR(a.y, b.y, eps);
  EXPECT_NEAR(a.z, b.z, eps);
}

class ObjLoader : public test_support::TempDirTest {
 protected:
  std::string write(const std::string& text, const std::string& name = "scene.obj") {
    std::ofstream out(dir_ / name, std::ios::binary);
    out << text;
    return (dir_ / name).string();
  }

  void expect_error(const std::string& file, const std::string& problem) {
    try {
      load_obj(file);
      ADD_FAILURE() << "no error loading " << file << " (expected '" << problem << "')";
    } catch (const SceneError& e) {
      const std::string msg = e.what();
      RecordProperty("message", msg);
      EXPECT_EQ(msg.rfind(file + ": ", 0), 0u) << msg;
      EXPECT_NE(msg.find(problem), std::string::npos) << "message: " << msg << "\nexpected: " << problem;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
  }
};

TEST_F(ObjLoader, SingleTriangle) {
  const std::string file = write("# a comment\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const Scene s = load_obj(file);
  EXPECT_EQ(s.source, file);
  ASSERT_EQ(s.triangles.size(), 1u);
  expect_vec3_near(s.triangles[0].v1, {1, 0, 0});
  ASSERT_EQ(s.instances.size(), 1u);
  EXPECT_EQ(s.instances[0].transform, glm::mat4(1.0f));
  EXPECT_EQ(s.roots, std::vector<int>{0});
  EXPECT_FALSE(s.has_instancing());
}

TEST_F(ObjLoader, PolygonsAreTriangulatedInFileOrder) {
  // A quad and a pentagon: 2 + 3 triangles; the quad cut along its first
  // vertex's diagonal, the pentagon by (v0, v2, v4) and then its two halves.
  const Scene s =
      load_obj(write("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 3 0 0\nv 3 1 0\nv 2.5 2 0\nv 2 1 0\n"
                     "f 1 2 3 4\nf 5 6 7 8 9\n"));
  ASSERT_EQ(s.meshes.size(), 1u);
  const Mesh& m = s.meshes[0];
  ASSERT_EQ(m.indices.size(), 5u);
  EXPECT_EQ(m.indices[0], glm::uvec3(0, 1, 2));
  EXPECT_EQ(m.indices[1], glm::uvec3(0, 2, 3));
  EXPECT_EQ(m.indices[2], glm::uvec3(4, 6, 8));
  EXPECT_EQ(m.indices[3], glm::uvec3(4, 5, 6));
  EXPECT_EQ(m.indices[4], glm::uvec3(6, 7, 8));
  EXPECT_EQ(s.triangles.size(), 5u);
}

// A concave face (a U) is ear-clipped: its fan covered the notch between the
// U's arms (6 triangles of area 11 for a polygon of area 7), so rays through
// the notch hit; a self-intersecting outline still gets its n - 2 triangles.
TEST_F(ObjLoader, ConcaveFacesAreEarClippedNotFanned) {
  const Scene s =
      load_obj(write("v 0 0 0\nv 3 0 0\nv 3 3 0\nv 2 3 0\nv 2 1 0\nv 1 1 0\nv 1 3 0\nv 0 3 0\n"
                     "f 1 2 3 4 5 6 7 8\n"));
  ASSERT_EQ(s.triangles.size(), 6u);
  double area = 0.0;
  const glm::vec3 notch(1.5f, 2.0f, 0.0f);
  for (const Triangle& t : s.triangles) {
    const glm::vec3 n = glm::cross(t.v1 - t.v0, t.v2 - t.v0);
    area += 0.5 * glm::length(n);
    EXPECT_GT(n.z, 0.0f) << "the face's winding";
    // The notch point lies outside every triangle (same side of all three edges means inside).
    const auto side = [&](const glm::vec3& a, const glm::vec3& b) { return glm::cross(b - a, notch - a).z > 0.0f; };
    EXPECT_FALSE(side(t.v0, t.v1) && side(t.v1, t.v2) && side(t.v2, t.v0));
  }
  EXPECT_NEAR(area, 7.0, 1e-5);
  // A bow tie (self-intersecting): no ear everywhere, still n - 2 triangles over its corners.
  const Scene bow = load_obj(write("v 0 0 0\nv 2 2 0\nv 2 0 0\nv 0 2 0\nv 1 -1 0\nf 1 2 3 4 5\n", "bow.obj"));
  EXPECT_EQ(bow.triangles.size(), 3u);
}

// tinyobjloader keeps a face's vertex count in an unsigned char: a face of
// 256 or more vertices lost triangles (300 gave 42) and misread the faces
// after it. Such faces are triangulated before it reads them: the same n - 2
// triangles tiling the face once, in its winding, and no triangle a sliver
// from the first corner across the face (a fan from it: a 10,000-gon took
// the K-D tree minutes). A circle of 65,100 corners or more is no longer
// convex in float (neighbours' bend is below float's precision): it is
// ear-clipped, round by round, and must be as good.
TEST_F(ObjLoader, FacesOfMoreThan255VerticesKeepEveryTriangle) {
  for (const int n : {255, 256, 257, 258, 300, 509, 510, 1000, 4000, 65100, 70000}) {
    SCOPED_TRACE(n);
    std::string text;
    std::vector<glm::dvec2> outline;  // the corners as the loader reads them (floats)
    for (int i = 0; i < n; ++i) {
      const double a = 6.283185307179586 * i / n;
      char line[80];
      std::snprintf(line, sizeof line, "v %.9g %.9g 0\n", std::cos(a), std::sin(a));
      text += line;
      outline.emplace_back(double(float(std::cos(a))), double(float(std::sin(a))));
    }
    text += "v 5 0 0\nv 6 0 0\nv 5 1 0\n";  // a triangle after the polygon
    std::string face = "f";
    for (int i = 1; i <= n; ++i) {
      face += ' ';
      face += std::to_string(i);
      if (i % 2 == 1) face += "/1";  // some references carry the texture coordinate
    }
    const std::string relative = "f -3 -2 -1\n";  // the triangle's vertices, counted back from here
    const Scene s = load_obj(write(text + "vt 0 0\n" + face + "\n" + relative, "poly" + std::to_string(n) + ".obj"));
    ASSERT_EQ(s.meshes.size(), 1u);
    const Mesh& m = s.meshes[0];
    ASSERT_EQ(m.indices.size(), static_cast<std::size_t>(n - 2 + 1));
    // Every triangle counter-clockwise like the face, their areas adding up to the face's, and the
    // corners the triangles use are the face's own (each at least once).
    double area = 0.0, face_area = 0.0;
    std::vector<int> used(static_cast<std::size_t>(n), 0);
    for (int k = 0; k < n - 2; ++k) {
      const glm::uvec3 t = m.indices[static_cast<std::size_t>(k)];
      ASSERT_TRUE(t.x < unsigned(n) && t.y < unsigned(n) && t.z < unsigned(n)) << "triangle " << k;
      ++used[t.x];
      ++used[t.y];
      ++used[t.z];
      const glm::dvec3 a(m.positions[t.x]), b(m.positions[t.y]), c(m.positions[t.z]);
      const double z = glm::cross(b - a, c - a).z;
      ASSERT_GT(z, 0.0) << "triangle " << k << " winds against the face or is flat";
      area += 0.5 * z;
    }
    for (int i = 0; i < n; ++i) {
      const glm::dvec2 a = outline[static_cast<std::size_t>(i)], b = outline[static_cast<std::size_t>((i + 1) % n)];
      face_area += 0.5 * (a.x * b.y - b.x * a.y);
    }
    EXPECT_NEAR(area, face_area, 1e-9 * n);
    EXPECT_EQ(std::count(used.begin(), used.end(), 0), 0);
    // The fan put corner 0 in all n - 2 triangles; halving puts a corner in a few per level.
    EXPECT_LE(*std::max_element(used.begin(), used.end()), 40);
    const glm::uvec3 last = m.indices.back();
    expect_vec3_near(m.positions[last.x], {5, 0, 0});
    expect_vec3_near(m.positions[last.y], {6, 0, 0});
    expect_vec3_near(m.positions[last.z], {5, 1, 0});
    EXPECT_TRUE(s.report.warnings.empty()) << s.report.warnings.front();
  }
}

// A concave face of more than 255 corners is ear-clipped as one outline: a comb of 100 teeth (403
// corners). Cut into pieces of 255 first (as before 2026-12-06), the pieces' chords ran across the gaps
// between the teeth and their triangles covered them.
TEST_F(ObjLoader, ConcaveFacesOfMoreThan255VerticesAreEarClippedWhole) {
  const int teeth = 100;
  std::vector<glm::dvec2> outline{{0, -1}, {teeth, -1}};
  for (int i = teeth - 1; i >= 0; --i) {
    outline.push_back({i + 1.0, 0.0});
    outline.push_back({i + 1.0, 1.0});
    outline.push_back({i + 0.5, 1.0});
    outline.push_back({i + 0.5, 0.0});
  }
  outline.push_back({0, 0});
  const std::size_t n = outline.size();
  ASSERT_GT(n, 255u);
  std::string text, face = "f";
  for (std::size_t i = 0; i < n; ++i) {
    text += "v " + std::to_string(outline[i].x) + " " + std::to_string(outline[i].y) + " 0\n";
    face += " " + std::to_string(i + 1);
  }
  const Scene s = load_obj(write(text + face + "\n", "comb.obj"));
  ASSERT_EQ(s.triangles.size(), n - 2);
  // Crossing-number test against the outline.
  const auto inside = [&](const glm::dvec2& q) {
    bool in = false;
    for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
      const glm::dvec2 a = outline[i], b = outline[j];
      if ((a.y > q.y) != (b.y > q.y) && q.x < (b.x - a.x) * (q.y - a.y) / (b.y - a.y) + a.x) in = !in;
    }
    return in;
  };
  double area = 0.0;
  for (std::size_t k = 0; k < s.triangles.size(); ++k) {
    const Triangle& t = s.triangles[k];
    const glm::dvec2 a(t.v0.x, t.v0.y), b(t.v1.x, t.v1.y), c(t.v2.x, t.v2.y);
    const double z = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    ASSERT_GT(z, 0.0) << "triangle " << k << " winds against the face or is flat";
    ASSERT_TRUE(inside((a + b + c) / 3.0)) << "triangle " << k << " lies outside the face";
    area += 0.5 * z;
  }
  EXPECT_NEAR(area, teeth * 1.0 + teeth * 0.5, 1e-6);  // the base and the teeth
}

TEST_F(ObjLoader, OneMeshPerShapeWithCompactedVertices) {
  const Scene s =
      load_obj(write("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 5\nv 1 0 5\nv 0 1 5\n"
                     "o first\nf 1 2 3\no second\nf 4 5 6\nf 6 5 4\n"));
  ASSERT_EQ(s.meshes.size(), 2u);
  EXPECT_EQ(s.meshes[0].name, "first");
  EXPECT_EQ(s.meshes[1].name, "second");
  EXPECT_EQ(s.meshes[1].positions.size(), 3u);  // only the vertices it uses
  EXPECT_EQ(s.meshes[1].indices[0], glm::uvec3(0, 1, 2));
  ASSERT_EQ(s.instances.size(), 2u);
  EXPECT_EQ(s.instances[1].first_triangle, 1u);
  EXPECT_EQ(s.instances[1].triangle_count, 2u);
  ASSERT_EQ(s.nodes.size(), 2u);
  EXPECT_EQ(s.nodes[1].name, "second");
  EXPECT_EQ(s.nodes[1].mesh, 1);
  EXPECT_FLOAT_EQ(s.triangles[1].v0.z, 5.0f);  // primitive ids in file order
}

TEST_F(ObjLoader, RelativeIndicesAndTextureNormalReferences) {
  const Scene s =
      load_obj(write("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n"
                     "f -3/1/1 -2/1/1 -1/1/1\nf 1//1 2//1 3//1\nf 1/1 2/1 3/1\n"));
  ASSERT_EQ(s.triangles.size(), 3u);
  expect_vec3_near(s.triangles[0].v2, {0, 1, 0});
}

TEST_F(ObjLoader, ForwardReferencesAreAllowed) {
  const Scene s = load_obj(write("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"));
  EXPECT_EQ(s.triangles.size(), 1u);
}

TEST_F(ObjLoader, CrLfAndLoneCrLineEndings) {
  EXPECT_EQ(load_obj(write("v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n")).triangles.size(), 1u);
  EXPECT_EQ(load_obj(write("v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r", "mac.obj")).triangles.size(), 1u);
  // Line numbers count \r\n once.
  expect_error(write("v 0 0 0\r\nv 1 0 0\r\nf 1 2 5\r\n", "numbers.obj"), "line 3: vertex index 5");
}

TEST_F(ObjLoader, ManyWarningsAreCapped) {
  std::string text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  for (int i = 0; i < 150; ++i) text += "usemtl missing" + std::to_string(i) + "\nf 1 2 3\n";
  const Scene s = load_obj(write(text));
  EXPECT_EQ(s.triangles.size(), 151u);
  ASSERT_EQ(s.report.warnings.size(), 101u);
  EXPECT_NE(s.report.warnings.back().find("more warnings"), std::string::npos) << s.report.warnings.back();
}

TEST_F(ObjLoader, MissingMaterialLibraryIsOnlyAWarning) {
  const Scene s = load_obj(write("mtllib absent.mtl\nusemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"));
  EXPECT_EQ(s.triangles.size(), 1u);
  std::string all;
  for (const std::string& w : s.report.warnings) {
    EXPECT_EQ(w.find('\n'), std::string::npos);
    all += w + "|";
  }
  EXPECT_NE(all.find("absent.mtl"), std::string::npos) << all;
}

TEST_F(ObjLoader, PresentMaterialLibraryLoadsQuietly) {
  write("newmtl red\nKd 1 0 0\n", "colours.mtl");
  const Scene s = load_obj(write("mtllib colours.mtl\nusemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"));
  EXPECT_EQ(s.triangles.size(), 1u);
  for (const std::string& w : s.report.warnings) EXPECT_EQ(w.find("colours.mtl"), std::string::npos) << w;
}

TEST_F(ObjLoader, LinesAndPointsAreSkippedWithAWarning) {
  const Scene s = load_obj(write("v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\np 3\nf 1 2 3\n"));
  EXPECT_EQ(s.triangles.size(), 1u);
  EXPECT_EQ(s.report.skipped_primitives, 2u);
  ASSERT_FALSE(s.report.warnings.empty());
  EXPECT_NE(s.report.warnings.back().find("2 line/point elements skipped"), std::string::npos);
}

// tinyobjloader drops a line whose statement it does not know without a word:
// a typo (`F`, `fo`, `f2`) lost faces silently. Such lines, and free-form
// geometry it does not read, are a warning; with no triangles left, the error
// says so. The statements of the specification it ignores (groups, smoothing,
// materials, texture vertices) are not.
TEST_F(ObjLoader, StatementsOBJDoesNotHaveAreAWarning) {
  const Scene s =
      load_obj(write("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvn 0 0 1\ng a\ns 1\no b\n"
                     "usemtl m\nf 1 2 3\nF 2 4 3\nfo 1 2 4\nf2 4 3\ncstype bspline\ncurv 0 1 1 2\n"));
  EXPECT_EQ(s.triangles.size(), 1u);
  const auto has = [&](const std::string& w) {
    return std::find(s.report.warnings.begin(), s.report.warnings.end(), w) != s.report.warnings.end();
  };
  EXPECT_TRUE(has("3 lines ignored: a statement OBJ does not have (first: line 12 'F')"));
  EXPECT_TRUE(has("free-form curves and surfaces not read (only polygonal faces are): 1 (first: line 16 'curv')"));
  try {
    load_obj(write("v 0 0 0\nv 1 0 0\nv 0 1 0\nF 1 2 3\n", "typo.obj"));
    ADD_FAILURE() << "a file of no faces loaded";
  } catch (const std::exception& e) {
    EXPECT_NE(
        std::string(e.what()).find(
            "typo.obj: scene contains no triangles; 1 line ignored: a statement OBJ does not have (first: line 4 'F')"),
        std::string::npos)
        << e.what();
  }
  const Scene clean = load_obj(write("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\ng a\ns off\nmtllib\nf 1 2 3\n", "c.obj"));
  for (const std::string& w : clean.report.warnings) EXPECT_EQ(w.find("statement OBJ"), std::string::npos) << w;
}

// Below 1e-34 float's denormals can make closest hits wrong (`verify` found some
// at 1e-36, none at 1e-35 or in the 1e-30 catalogue case): load_scene says so.
TEST_F(ObjLoader, ASceneTooSmallForFloatIsAWarning) {
  const auto warned = [](const Scene& s) {
    for (const std::string& w : s.report.warnings)
      if (w.find("float's denormals can make closest hits wrong") != std::string::npos) return true;
    return false;
  };
  EXPECT_TRUE(warned(load_scene(write("v 0 0 0\nv 1e-36 0 0\nv 0 1e-36 0\nf 1 2 3\n", "tiny.obj"))));
  EXPECT_FALSE(warned(load_scene(write("v 0 0 0\nv 1e-30 0 0\nv 0 1e-30 0\nf 1 2 3\n", "small.obj"))));
  EXPECT_FALSE(warned(load_scene(write("v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\n", "point.obj")))) << "a point spans 0";
}

TEST_F(ObjLoader, NonFiniteVerticesAreDroppedAndCounted) {
  // tinyobjloader alone would read "nan" and "inf" as 0 and keep the triangles.
  const Scene s =
      load_obj(write("v 0 0 0\nv 1 0 0\nv 0 1 0\nv nan 0 0\nv 0 -inf 0\nv 1e999 0 0\n"
                     "f 1 2 3\nf 1 2 4\nf 1 5 3\nf 6 2 3\n"));
  EXPECT_EQ(s.triangles.size(), 1u);
  EXPECT_EQ(s.report.dropped_nonfinite, 3u);
}

TEST_F(ObjLoader, DegenerateTrianglesAreKeptAndCounted) {
  const Scene s = load_obj(write("v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n"));
  EXPECT_EQ(s.triangles.size(), 2u);
  EXPECT_EQ(s.report.degenerate, 1u);
}

// --- errors ---------------------------------------------------------------------

TEST_F(ObjLoader, MissingFile) {
  expect_error((dir_ / "absent.obj").string(), "no such file");
}

TEST_F(ObjLoader, IndexOutOfRange) {
  expect_error(write("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"),
               "line 4: vertex index 9 is out of range (the file has 3 vertices)");
}

TEST_F(ObjLoader, RelativeIndexOutOfRange) {
  expect_error(write("v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\n"),
               "line 3: relative vertex index -3 is out of range (only 2 vertices so far)");
}

TEST_F(ObjLoader, ZeroIndex) {
  expect_error(write("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"), "line 4: vertex index 0 is invalid");
}

TEST_F(ObjLoader, MalformedVertexLine) {
  expect_error(write("v 0 0 0\nv 1 zero 0\n"), "line 2: vertex coordinate 'zero' is not a number");
  expect_error(write("v 0 0\n", "short.obj"), "line 1: vertex has 2 coordinates (expected at least 3)");
  expect_error(write("v 0x10 0 0\n", "hex.obj"), "vertex coordinate '0x10' is not a number");
  expect_error(write(std::string("v 1 2\0 3\n", 10), "nul.obj"), "vertex coordinate '2?' is not a number");
}

TEST_F(ObjLoader, MalformedFaceLine) {
  expect_error(write("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 three\n"), "line 4: malformed vertex reference 'three'");
  expect_error(write("v 0 0 0\nv 1 0 0\nf 1 2\n", "two.obj"), "line 3: face has 2 vertices (expected at least 3)");
  expect_error(write("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n", "four.obj"), "malformed vertex reference '1/1/1/1'");
  expect_error(write("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/ 2 3\n", "slash.obj"), "malformed vertex reference '1/'");
  expect_error(write("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1/ 2 3\n", "trailing.obj"),
               "malformed vertex reference '1/1/'");
  expect_error(write("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//0 2 3\n", "normal.obj"),
               "texture/normal index 0 in '1//0' is invalid");
}

TEST_F(ObjLoader, EmptySceneIsAnError) {
  expect_error(write(""), "scene contains no triangles");
  expect_error(write("v 0 0 0\nv 1 0 0\nl 1 2\n", "lines.obj"), "scene contains no triangles");
  expect_error(write("v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "allnan.obj"),
               "scene contains no triangles (1 triangle dropped: a NaN or infinite vertex)");
  expect_error(write("v 1e39 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\n", "overflow.obj"),
               "scene contains no triangles (2 triangles dropped: NaN or infinite vertices)");
}

}  // namespace
}  // namespace unity_test_obj_loader
