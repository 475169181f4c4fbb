// Malformed files of every kind the loaders accept (issue 9): each gives one
// line "<file>: <problem>", never a crash, a hang or another exception type.
// Complements test_gltf_loader / test_obj_loader / test_ray_file (which cover
// wrong magic, chunk lengths, accessor ranges, cycles, deep chains, missing
// buffers...) with exhaustive truncation of valid files at every length and
// the accessor/stride/mode/non-finite cases they do not. Every file is made
// by the test in its own temporary directory.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/query/ray_file.h"
#include "core/scene/load.h"
#include "tests/core/base64.h"
#include "tests/support/temp_dir.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_malformed_files {

using namespace accelviz;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

class Malformed : public test_support::TempDirTest {
 protected:
  std::string write(const std::string& name, const std::string& bytes) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return p.string();
  }

  /// Loads `file` with `load`; returns the error message ("" when it loaded).
  /// Fails the test on any other exception type and on a message that is not
  /// one line starting with the file's path.
  template <class Error, class Fn>
  std::string outcome(const std::string& file, Fn&& load) {
    try {
      load(file);
      return "";
    } catch (const Error& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind(file + ": ", 0), 0u) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
      EXPECT_GT(msg.size(), file.size() + 2) << "names the problem: " << msg;
      return msg;
    } catch (const std::exception& e) {
      ADD_FAILURE() << file << ": unexpected exception type: " << e.what();
      return "?";
    }
  }

  std::string gltf_error(const std::string& file) {
    return outcome<SceneError>(file, [](const std::string& f) { (void)load_gltf(f); });
  }

  void expect_gltf_error(const std::string& file, const std::string& problem) {
    const std::string msg = gltf_error(file);
    EXPECT_NE(msg.find(problem), std::string::npos) << "message: '" << msg << "'\nexpected: " << problem;
  }
};

std::string u32(std::uint32_t v) {
  std::string s;
  for (int k = 0; k < 4; ++k) s += static_cast<char>((v >> (8 * k)) & 0xFF);
  return s;
}

// One triangle, indexed (u16), positions then indices in one buffer.
struct Doc {
  json j;
  std::string bin;
};

Doc triangle_doc() {
  Doc d;
  const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const std::uint16_t idx[4] = {0, 1, 2, 0};  // padded to 8 bytes
  d.bin.assign(reinterpret_cast<const char*>(pos), sizeof pos);
  d.bin.append(reinterpret_cast<const char*>(idx), sizeof idx);
  d.j = {{"asset", {{"version", "2.0"}}},
         {"buffers", {{{"byteLength", d.bin.size()}}}},
         {"bufferViews",
          {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 36}},
           {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 6}}}},
         {"accessors",
          {{{"bufferView", 0}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}},
           {{"bufferView", 1}, {"componentType", 5123}, {"count", 3}, {"type", "SCALAR"}}}},
         {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}}}}}},
         {"nodes", {{{"mesh", 0}}}},
         {"scenes", {{{"nodes", {0}}}}},
         {"scene", 0}};
  return d;
}

std::string glb(const Doc& d) {
  std::string js = d.j.dump();
  while (js.size() % 4) js += ' ';
  std::string bin = d.bin;
  while (bin.size() % 4) bin += '\0';
  const std::string body = u32(static_cast<std::uint32_t>(js.size())) + u32(0x4E4F534A) + js +
                           u32(static_cast<std::uint32_t>(bin.size())) + u32(0x004E4942) + bin;
  return u32(0x46546C67) + u32(2) + u32(static_cast<std::uint32_t>(12 + body.size())) + body;
}

std::string gltf_text(Doc d) {
  d.j["buffers"][0]["uri"] = "data:application/octet-stream;base64," + test::base64(d.bin);
  return d.j.dump();
}

}  // namespace

// ------------------------------------------------------------ truncation

TEST_F(Malformed, ValidFilesLoad) {
  EXPECT_EQ(gltf_error(write("ok.glb", glb(triangle_doc()))), "");
  EXPECT_EQ(gltf_error(write("ok.gltf", gltf_text(triangle_doc()))), "");
}

TEST_F(Malformed, GlbTruncatedAtEveryLength) {
  const std::string full = glb(triangle_doc());
  for (std::size_t n = 0; n < full.size(); ++n) {
    const std::string msg = gltf_error(write("t.glb", full.substr(0, n)));
    EXPECT_FALSE(msg.empty()) << "a GLB cut to " << n << " of " << full.size() << " bytes loaded";
  }
}

TEST_F(Malformed, GltfJsonTruncatedAtEveryLength) {
  const std::string full = gltf_text(triangle_doc());
  for (std::size_t n = 0; n < full.size(); ++n) {
    const std::string msg = gltf_error(write("t.gltf", full.substr(0, n)));
    EXPECT_FALSE(msg.empty()) << "a glTF cut to " << n << " of " << full.size() << " bytes loaded";
  }
}

TEST_F(Malformed, ObjTruncatedAtEveryLengthNeverCrashes) {
  const std::string full = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1 3/1/1\nf -3 -2 -1\n";
  int loaded = 0;
  for (std::size_t n = 0; n < full.size(); ++n) {
    const std::string f = write("t.obj", full.substr(0, n));
    loaded += outcome<SceneError>(f, [](const std::string& p) { (void)load_obj(p); }).empty();
  }
  EXPECT_GT(loaded, 0);  // prefixes ending after the first face are valid OBJ
  // Cut inside the last face's indices: "f -3 -2 -" is a malformed face.
  const std::string cut = full.substr(0, full.size() - 2);
  const std::string msg = outcome<SceneError>(write("cut.obj", cut), [](const std::string& p) { (void)load_obj(p); });
  EXPECT_FALSE(msg.empty()) << "'" << cut << "' loaded";
}

TEST_F(Malformed, RayFilesTruncatedAtEveryLength) {
  const std::vector<Ray> rays = {Ray({0, 0, 0}, {0, 0, 1}), Ray({1, 2, 3}, {1, 0, 0}, 0.5f, 9.0f)};
  Hit h;
  h.prim = 3;
  h.t = 1.5f;
  const std::vector<Hit> hits = {h, Hit{}};
  const std::string rf = (dir_ / "full.rays").string(), hf = (dir_ / "full.hits").string();
  write_rays(rf, rays);
  write_hits(hf, hits);
  for (const auto& [file, which] : std::vector<std::pair<std::string, int>>{{rf, 0}, {hf, 1}}) {
    const int reader = which;  // a lambda cannot capture a structured binding before clang 16
    std::ifstream in(file, std::ios::binary);
    const std::string full((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_GT(full.size(), kRayFileHeaderBytes);
    for (std::size_t n = 0; n < full.size(); ++n) {
      const std::string f = write("t.bin", full.substr(0, n));
      const std::string msg = outcome<RayFileError>(f, [&](const std::string& p) {
        if (reader == 0)
          (void)read_rays(p);
        else
          (void)read_hits(p);
      });
      EXPECT_FALSE(msg.empty()) << file << " cut to " << n << " bytes was read";
    }
  }
}

// ------------------------------------------------------------ accessors

TEST_F(Malformed, IndexAccessorWithFloatComponentType) {
  Doc d = triangle_doc();
  d.j["accessors"][1]["componentType"] = 5126;
  d.j["bufferViews"][1]["byteLength"] = 8;  // room for 2 floats only: still wrong either way
  expect_gltf_error(write("a.gltf", gltf_text(d)), "accessor 1");
}

TEST_F(Malformed, PositionAccessorOfWrongType) {
  for (const char* type : {"VEC2", "SCALAR", "MAT4"}) {
    Doc d = triangle_doc();
    d.j["accessors"][0]["type"] = type;
    expect_gltf_error(write(std::string("p") + type + ".gltf", gltf_text(d)), "accessor 0");
  }
}

TEST_F(Malformed, UnknownComponentType) {
  Doc d = triangle_doc();
  d.j["accessors"][0]["componentType"] = 1234;
  EXPECT_FALSE(gltf_error(write("c.gltf", gltf_text(d))).empty());
}

TEST_F(Malformed, ByteStrideOutOfRange) {
  // Smaller than the element, not a multiple of 4, larger than glTF's 252,
  // and one that walks the last element past the view.
  for (int stride : {4, 13, 256, 24}) {
    Doc d = triangle_doc();
    d.j["bufferViews"][0]["byteStride"] = stride;
    EXPECT_FALSE(gltf_error(write(std::to_string(stride) + "s.gltf", gltf_text(d))).empty())
        << "byteStride " << stride << " loaded";
  }
  // tinygltf's own words said "must be the multiple of 4" of 300, a multiple of 4.
  Doc d = triangle_doc();
  d.j["bufferViews"][0]["byteStride"] = 300;
  expect_gltf_error(write("300s.gltf", gltf_text(d)),
                    "a bufferView's byteStride 300 is not a multiple of 4 from 4 to 252");
}

TEST_F(Malformed, UrisTinygltfDoesNotReadAreNamedForWhatTheyAre) {
  // They fell through to a file lookup: "external buffer file 'data:...' not found".
  Doc other = triangle_doc();
  std::string text = gltf_text(other);
  const std::string from = "data:application/octet-stream;base64,";
  text.replace(text.find(from), from.size(), "data:application/x-binary;base64,");
  expect_gltf_error(write("media.gltf", text), "a buffer's data URI is not one that can be read");
  Doc web = triangle_doc();
  web.j["buffers"][0]["uri"] = "http://example.org/x.bin";
  expect_gltf_error(write("web.gltf", web.j.dump()), "a buffer's URI scheme 'http' is not supported");
  expect_gltf_error(write("empty.gltf", "{}"), "the JSON is empty or too short (a glTF needs at least \"asset\"");
}

TEST_F(Malformed, AccessorOffsetsOutOfRange) {
  for (int off : {36, 1000, -4}) {
    Doc d = triangle_doc();
    d.j["accessors"][0]["byteOffset"] = off;
    EXPECT_FALSE(gltf_error(write(std::to_string(off + 10) + "o.gltf", gltf_text(d))).empty())
        << "accessor byteOffset " << off;
  }
  Doc neg = triangle_doc();
  neg.j["accessors"][0]["byteOffset"] = -4;
  expect_gltf_error(write("neg.gltf", gltf_text(neg)), "negative byteOffset (-4)");
  Doc d = triangle_doc();
  d.j["bufferViews"][1]["byteOffset"] = 1u << 31;
  EXPECT_FALSE(gltf_error(write("v.gltf", gltf_text(d))).empty());
}

TEST_F(Malformed, AccessorCountsOutOfRange) {
  for (long long count : {4LL, -1LL, 0LL, 1LL << 40}) {
    Doc d = triangle_doc();
    d.j["accessors"][1]["count"] = count;
    const std::string msg = gltf_error(write("n.gltf", gltf_text(d)));
    if (count != 0) {
      EXPECT_FALSE(msg.empty()) << "index count " << count;
    }
  }
}

TEST_F(Malformed, IndexCountNotAMultipleOfThree) {
  Doc d = triangle_doc();
  d.j["accessors"][1]["count"] = 2;
  // Either an error or the incomplete triangle dropped; never a crash or a read past the end.
  const std::string msg = gltf_error(write("m.gltf", gltf_text(d)));
  if (msg.empty()) {
    const Scene s = load_gltf((dir_ / "m.gltf").string());
    EXPECT_TRUE(s.triangles.empty());
  }
}

// ------------------------------------------------------------ modes, values, nodes

TEST_F(Malformed, UnknownPrimitiveMode) {
  Doc d = triangle_doc();
  d.j["meshes"][0]["primitives"][0]["mode"] = 9;
  EXPECT_FALSE(gltf_error(write("mode.gltf", gltf_text(d))).empty());
}

TEST_F(Malformed, NonFiniteNodeTransforms) {
  // JSON has no NaN/inf literal; 1e999 overflows to inf when parsed.
  for (const char* field : {"translation", "scale", "matrix"}) {
    Doc d = triangle_doc();
    std::string text = gltf_text(d);
    const std::string node = "{\"mesh\":0}";
    const std::string bad = std::string(field) == "matrix"
                                ? "{\"mesh\":0,\"matrix\":[1e999,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1]}"
                                : "{\"mesh\":0,\"" + std::string(field) + "\":[1e999,1,1]}";
    const std::size_t at = text.find(node);
    ASSERT_NE(at, std::string::npos);
    text.replace(at, node.size(), bad);
    const std::string f = write(std::string(field) + ".gltf", text);
    const std::string msg = gltf_error(f);
    if (msg.empty()) {
      // Loaded: then every non-finite triangle must have been dropped.
      const Scene s = load_gltf(f);
      for (const Triangle& t : s.triangles) {
        EXPECT_TRUE(std::isfinite(t.v0.x) && std::isfinite(t.v1.y) && std::isfinite(t.v2.z)) << field;
      }
    }
  }
}

TEST_F(Malformed, NegativeLengthsCountsAndIndicesAreNamed) {
  // tinygltf ignores a negative value of these (keeping 0); the loader must not.
  struct Case {
    const char* where;
    const char* key;
  } cases[] = {{"bufferViews", "byteLength"},
               {"bufferViews", "byteOffset"},
               {"accessors", "count"},
               {"accessors", "bufferView"}};
  for (const Case& c : cases) {
    Doc d = triangle_doc();
    d.j[c.where][0][c.key] = -8;
    expect_gltf_error(write(std::string(c.key) + ".gltf", gltf_text(d)), std::string("negative ") + c.key + " (-8)");
  }
  Doc d = triangle_doc();
  d.j["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = -1;
  expect_gltf_error(write("pos.gltf", gltf_text(d)), "negative POSITION (-1)");
  // A negative translation is an ordinary value.
  Doc t = triangle_doc();
  t.j["nodes"][0]["translation"] = {-1, -2, -3};
  EXPECT_EQ(gltf_error(write("t.gltf", gltf_text(t))), "");
}

TEST_F(Malformed, NegativeAndHugeNodeIndices) {
  for (long long child : {-1LL, 1LL << 40}) {
    Doc d = triangle_doc();
    d.j["nodes"][0]["children"] = {child};
    EXPECT_FALSE(gltf_error(write("c.gltf", gltf_text(d))).empty()) << child;
  }
  Doc d = triangle_doc();
  d.j["scenes"][0]["nodes"] = {5};
  EXPECT_FALSE(gltf_error(write("r.gltf", gltf_text(d))).empty());
}

TEST_F(Malformed, IndicesThatAreNotWholeNumbersOrBeyondAnIntAreNamed) {
  // tinygltf keeps an index in an int and skips a float or string one: "mesh": 4294967296 loaded mesh 0,
  // "mesh": 0.0 dropped the node's mesh, "indices": 1.0 read the positions without their index buffer.
  Doc big = triangle_doc();
  big.j["nodes"][0]["mesh"] = 4294967296LL;
  expect_gltf_error(write("big.gltf", gltf_text(big)), "\"mesh\" 4294967296 is beyond any index");
  Doc point = triangle_doc();
  point.j["nodes"][0]["mesh"] = 0.0;
  expect_gltf_error(write("point.gltf", gltf_text(point)), "\"mesh\" is 0.0: an index is a whole number");
  Doc pos = triangle_doc();
  pos.j["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 0.5;
  expect_gltf_error(write("pos.gltf", gltf_text(pos)), "\"POSITION\" is 0.5");
  Doc str = triangle_doc();
  str.j["scenes"][0]["nodes"] = {"0"};
  expect_gltf_error(write("str.gltf", gltf_text(str)), "\"nodes\" is the string \"0\", not a number");
  // Free-form extras may use these names for anything.
  Doc extras = triangle_doc();
  extras.j["nodes"][0]["extras"] = {{"mesh", "a name"}, {"count", -1}, {"node", 2.5}, {"children", {"x"}}};
  EXPECT_EQ(gltf_error(write("extras.gltf", gltf_text(extras))), "");
}

TEST_F(Malformed, PrimitivesSharingOneHugeAccessorAreRefusedBeforeAnyIsRead) {
  // 300 primitives of one mesh on one accessor of 3M indices: 300M triangles from a 12 MB file took 3 GB
  // before the world-triangle limit (which counts instances) could see them.
  Doc d = triangle_doc();
  d.j["accessors"][1]["count"] = 3'000'000;
  const json prim = d.j["meshes"][0]["primitives"][0];
  d.j["meshes"][0]["primitives"] = json::array();
  for (int k = 0; k < 300; ++k) d.j["meshes"][0]["primitives"].push_back(prim);
  expect_gltf_error(write("prims.glb", glb(d)),
                    "the meshes' primitives declare 300000000 triangles (their accessors' counts), more than the "
                    "limit of 268435456");
}

TEST_F(Malformed, GlbChunkTypeAndAlignment) {
  std::string bytes = glb(triangle_doc());
  std::string wrong_type = bytes;
  wrong_type[16] = 'X';  // JSON chunk type
  EXPECT_FALSE(gltf_error(write("type.glb", wrong_type)).empty());
  std::string wrong_version = bytes;
  wrong_version[4] = 1;
  EXPECT_FALSE(gltf_error(write("version.glb", wrong_version)).empty());
  std::string total_short = bytes;
  total_short[8] = static_cast<char>(static_cast<unsigned char>(total_short[8]) - 4);
  EXPECT_FALSE(gltf_error(write("total.glb", total_short)).empty());
}

// ------------------------------------------------------------ files a scene names

// The files a .gltf or an .obj names are read only when they are regular
// files: a FIFO blocked the loader (tinygltf and tinyobjloader open what they
// are given), a directory asked for an allocation of SIZE_MAX ("out of
// memory"), /dev/zero grew an .mtl line without bound.
TEST_F(Malformed, ExternalFilesThatAreNotRegularFilesNeitherBlockNorAllocate) {
  ASSERT_EQ(::mkfifo((dir_ / "buf.fifo").c_str(), 0600), 0) << std::strerror(errno);
  ASSERT_EQ(::mkfifo((dir_ / "m.fifo").c_str(), 0600), 0) << std::strerror(errno);
  fs::create_directories(dir_ / "adir");
  Doc d = triangle_doc();
  for (const char* uri : {"buf.fifo", "adir", "."}) {
    SCOPED_TRACE(uri);
    d.j["buffers"][0]["uri"] = uri;
    expect_gltf_error(
        write(std::string("ext-") + (uri[0] == '.' ? "dot" : uri) + ".gltf", d.j.dump()),
        std::string(uri) + (uri[0] == 'b' ? " : is not a regular file" : " : is a directory, not a file"));
  }
  // Images are never decoded: one that is a FIFO or a directory is a warning.
  Doc img = triangle_doc();
  img.j["images"] = {{{"uri", "buf.fifo"}}, {{"uri", "adir"}}};
  const Scene with_images = load_gltf(write("images.gltf", gltf_text(img)));
  EXPECT_EQ(with_images.triangles.size(), 1u);

  // OBJ: the .mtl named by mtllib is a FIFO, a directory, /dev/zero: a warning each, the geometry loads.
  const std::string dev_zero = fs::relative("/dev/zero", dir_).string();  // mtllib names are relative to the .obj
  for (const std::string& mtl : {std::string("m.fifo"), std::string("adir"), dev_zero}) {
    SCOPED_TRACE(mtl);
    const Scene s = load_obj(write("m.obj", "mtllib " + mtl + "\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"));
    EXPECT_EQ(s.triangles.size(), 1u);
    bool said = false;
    for (const std::string& w : s.report.warnings)
      said |= w.find("[ " + mtl + " ] is") != std::string::npos && w.find("; materials skipped") != std::string::npos;
    EXPECT_TRUE(said) << "a warning names the .mtl";
  }
}

// An OBJ saved with a UTF-8 byte order mark: the mark is not part of the
// first `v` line (which was skipped, so an index to the last vertex read as
// out of range).
TEST_F(Malformed, ObjWithAByteOrderMarkLoadsEveryVertex) {
  const Scene s = load_obj(write("bom.obj", "\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n"));
  ASSERT_EQ(s.triangles.size(), 1u);
  EXPECT_EQ(s.triangles[0].v0, glm::vec3(0, 0, 0));
}

}  // namespace unity_test_malformed_files
