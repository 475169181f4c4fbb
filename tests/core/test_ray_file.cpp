#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "core/query/ray_file.h"
#include "tests/support/temp_dir.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_ray_file {

using namespace accelviz;
namespace fs = std::filesystem;

namespace {

/// A fresh directory per test under the system temp dir, removed afterwards.
class RayFileTest : public test_support::TempDirTest {};

std::vector<std::uint8_t> slurp(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void spit(const std::string& p, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

void poke_f32(std::vector<std::uint8_t>& bytes, std::size_t offset, float v) {
  std::uint32_t u;
  std::memcpy(&u, &v, 4);
  for (int i = 0; i < 4; ++i) bytes[offset + i] = static_cast<std::uint8_t>(u >> (8 * i));
}

/// Expects `fn` to throw a RayFileError whose one-line message starts with the
/// file name and contains `needle`.
template <typename Fn>
void expect_error(const std::string& file, const std::string& needle, Fn&& fn) {
  try {
    fn();
    ADD_FAILURE() << "no error for " << needle;
  } catch (const RayFileError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(file + ": ", 0), 0u) << msg;
    EXPECT_NE(msg.find(needle), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

std::vector<Ray> random_rays(std::size_t n) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-10.0f, 10.0f);
  std::vector<Ray> rays;
  for (std::size_t i = 0; i < n; ++i) {
    glm::vec3 d{u(rng), u(rng), u(rng)};
    if (glm::dot(d, d) == 0.0f) d = {1, 0, 0};
    const float t0 = std::abs(u(rng)) * 0.1f;
    rays.push_back(Ray{glm::vec3{u(rng), u(rng), u(rng)}, d, t0, i % 3 == 0 ? kInfinity : t0 + std::abs(u(rng))});
  }
  return rays;
}

}  // namespace

TEST_F(RayFileTest, RaysRoundTrip) {
  const std::vector<Ray> rays = random_rays(1000);
  write_rays(path("a.rays"), rays);
  EXPECT_EQ(fs::file_size(path("a.rays")), kRayFileHeaderBytes + rays.size() * kRayRecordBytes);
  const std::vector<Ray> back = read_rays(path("a.rays"));
  ASSERT_EQ(back.size(), rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) {
    EXPECT_EQ(back[i].origin, rays[i].origin);
    EXPECT_EQ(back[i].direction, rays[i].direction);
    EXPECT_EQ(back[i].tmin, rays[i].tmin);
    EXPECT_EQ(back[i].tmax, rays[i].tmax);
    EXPECT_EQ(back[i].inv_dir, rays[i].inv_dir);
  }
}

TEST_F(RayFileTest, UnboundedTmaxIsWrittenAs1e30AndReadAsInfinity) {
  const std::vector<Ray> rays = {Ray({0, 0, 0}, {0, 0, 1}, 0.0f, kInfinity)};
  write_rays(path("u.rays"), rays);
  const std::vector<std::uint8_t> bytes = slurp(path("u.rays"));
  ASSERT_EQ(bytes.size(), 48u);
  float tmax;
  std::memcpy(&tmax, bytes.data() + 16 + 28, 4);
  EXPECT_EQ(tmax, 1e30f);
  EXPECT_TRUE(std::isinf(read_rays(path("u.rays"))[0].tmax));
}

TEST_F(RayFileTest, HeaderLayoutIsLittleEndian) {
  write_rays(path("h.rays"), random_rays(3));
  const std::vector<std::uint8_t> b = slurp(path("h.rays"));
  EXPECT_EQ(std::string(b.begin(), b.begin() + 4), "RAYS");
  EXPECT_EQ(b[4], 1);
  EXPECT_EQ(b[5] | b[6] | b[7], 0);
  EXPECT_EQ(b[8], 3);
  for (int i = 9; i < 16; ++i) EXPECT_EQ(b[i], 0);
}

TEST_F(RayFileTest, HitsAndOcclusionRoundTrip) {
  std::vector<Hit> hits(4);
  hits[0].prim = 7;
  hits[0].t = 2.5f;
  hits[2].prim = 0;
  hits[2].t = 0.125f;
  write_hits(path("a.hits"), std::span<const Hit>(hits));
  const std::vector<std::uint8_t> raw = slurp(path("a.hits"));
  ASSERT_EQ(raw.size(), 16u + 4 * 8);
  EXPECT_EQ(std::string(raw.begin(), raw.begin() + 4), "HITS");
  EXPECT_EQ(raw[16 + 8], 0xFF);  // miss id
  float t;
  std::memcpy(&t, raw.data() + 16 + 8 + 4, 4);
  EXPECT_EQ(t, 1e30f);
  const std::vector<HitRecord> back = read_hits(path("a.hits"));
  ASSERT_EQ(back.size(), 4u);
  EXPECT_EQ(back[0], (HitRecord{7, 2.5f}));
  EXPECT_FALSE(back[1].valid());
  EXPECT_TRUE(std::isinf(back[1].t));
  EXPECT_EQ(back[2], (HitRecord{0, 0.125f}));

  const std::vector<std::uint8_t> occ = {1, 0, 0, 1, 1};
  write_occlusion(path("a.occl"), occ);
  EXPECT_EQ(fs::file_size(path("a.occl")), 16u + 5u);
  EXPECT_EQ(read_occlusion(path("a.occl")), occ);
}

TEST_F(RayFileTest, EmptyFilesRoundTrip) {
  write_rays(path("e.rays"), {});
  EXPECT_TRUE(read_rays(path("e.rays")).empty());
}

TEST_F(RayFileTest, WritersRefuseToOverwriteUnlessForced) {
  write_rays(path("x.rays"), random_rays(2));
  expect_error(path("x.rays"), "exists", [&] { write_rays(path("x.rays"), random_rays(5)); });
  EXPECT_EQ(read_rays(path("x.rays")).size(), 2u);  // untouched
  write_rays(path("x.rays"), random_rays(5), /*overwrite=*/true);
  EXPECT_EQ(read_rays(path("x.rays")).size(), 5u);
  std::vector<Hit> hits(1);
  write_hits(path("x.hits"), std::span<const Hit>(hits));
  expect_error(path("x.hits"), "exists", [&] { write_hits(path("x.hits"), std::span<const Hit>(hits)); });
}

// Outputs are regular files: a FIFO or a device under the output's name is
// refused before anything is opened (a FIFO blocked the writer; a failed
// write removed the node), with --force too.
TEST_F(RayFileTest, WritersRefuseFifosAndDevices) {
  const std::string fifo = path("out.hits");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  std::vector<Hit> hits(1);
  for (bool force : {false, true}) {
    expect_error(fifo, "is not a regular file", [&] { write_hits(fifo, std::span<const Hit>(hits), force); });
    expect_error(fifo, "is not a regular file", [&] { write_rays(fifo, random_rays(2), force); });
  }
  EXPECT_TRUE(std::filesystem::is_fifo(fifo)) << "the FIFO is still there";
  expect_error("/dev/null", "is not a regular file",
               [&] { write_hits("/dev/null", std::span<const Hit>(hits), /*overwrite=*/true); });
}

// 1e30 is the miss's t in a HITS file: a hit at or beyond it cannot be
// written (it was clamped to 1e30 with its id kept, a record read_hits then
// refused as half a miss).
TEST_F(RayFileTest, HitsAtOrBeyond1e30AreRefusedNotClamped) {
  for (float t : {1e30f, 1.06e33f, kInfinity}) {
    SCOPED_TRACE(t);
    const std::vector<HitRecord> records{{3, 2.0f}, {7, t}};
    expect_error(path("far.hits"), "hit 1 at t", [&] { write_hits(path("far.hits"), records); });
    EXPECT_FALSE(std::filesystem::exists(path("far.hits"))) << "nothing written";
  }
  const std::vector<HitRecord> near{{7, 9.9e29f}};
  write_hits(path("near.hits"), near);
  EXPECT_EQ(read_hits(path("near.hits")), near);
}

TEST_F(RayFileTest, MissingFile) {
  expect_error(path("none.rays"), "no such file", [&] { read_rays(path("none.rays")); });
}

TEST_F(RayFileTest, TooShort) {
  spit(path("s.rays"), {'R', 'A', 'Y', 'S', 1, 0});
  expect_error(path("s.rays"), "too short", [&] { read_rays(path("s.rays")); });
  spit(path("empty.rays"), {});
  expect_error(path("empty.rays"), "too short", [&] { read_rays(path("empty.rays")); });
}

TEST_F(RayFileTest, WrongMagic) {
  write_rays(path("m.rays"), random_rays(2));
  expect_error(path("m.rays"), "not a HITS file", [&] { read_hits(path("m.rays")); });
  std::vector<std::uint8_t> b = slurp(path("m.rays"));
  b[0] = 0x00;
  spit(path("m2.rays"), b);
  expect_error(path("m2.rays"), "magic", [&] { read_rays(path("m2.rays")); });
}

TEST_F(RayFileTest, WrongVersion) {
  write_rays(path("v.rays"), random_rays(2));
  std::vector<std::uint8_t> b = slurp(path("v.rays"));
  b[4] = 2;
  spit(path("v.rays"), b);
  expect_error(path("v.rays"), "unsupported version 2", [&] { read_rays(path("v.rays")); });
}

TEST_F(RayFileTest, CountDisagreesWithLength) {
  write_rays(path("c.rays"), random_rays(4));
  std::vector<std::uint8_t> b = slurp(path("c.rays"));
  // A huge count must be rejected before any allocation.
  for (int i = 8; i < 16; ++i) b[i] = 0xFF;
  spit(path("huge.rays"), b);
  expect_error(path("huge.rays"), "header says", [&] { read_rays(path("huge.rays")); });
  // A truncated payload.
  b = slurp(path("c.rays"));
  b.resize(b.size() - 5);
  spit(path("trunc.rays"), b);
  expect_error(path("trunc.rays"), "bytes follow the header", [&] { read_rays(path("trunc.rays")); });
  // Trailing bytes.
  b = slurp(path("c.rays"));
  b.resize(b.size() + 32);
  spit(path("long.rays"), b);
  expect_error(path("long.rays"), "header says 4 rays", [&] { read_rays(path("long.rays")); });
}

TEST_F(RayFileTest, InvalidRays) {
  write_rays(path("base.rays"), random_rays(3));
  const std::vector<std::uint8_t> base = slurp(path("base.rays"));
  const std::size_t ray1 = 16 + 32;  // second ray's record
  struct Case {
    const char* name;
    std::size_t offset;
    float value;
    const char* needle;
  };
  const Case cases[] = {
      {"nan_origin", ray1 + 4, std::nanf(""), "ray 1: NaN in origin"},
      {"nan_dir", ray1 + 20, std::nanf(""), "ray 1: NaN in direction"},
      {"inf_origin", ray1 + 0, kInfinity, "ray 1: infinite origin"},
      {"nan_tmax", ray1 + 28, std::nanf(""), "ray 1: NaN in tmin/tmax"},
      {"tmin_gt_tmax", ray1 + 12, 1e31f, "ray 1: tmin > tmax"},
      // Behind the origin the structures disagreed (t = -1, t = +1 or a miss): refused.
      {"negative_tmin", ray1 + 12, -1.0f, "ray 1: tmin -1 is negative (rays start at their origin"},
  };
  for (const Case& c : cases) {
    std::vector<std::uint8_t> b = base;
    poke_f32(b, c.offset, c.value);
    const std::string p = path(std::string(c.name) + ".rays");
    spit(p, b);
    expect_error(p, c.needle, [&] { read_rays(p); });
  }
  std::vector<std::uint8_t> b = base;
  for (int k = 0; k < 3; ++k) poke_f32(b, ray1 + 16 + 4 * k, 0.0f);
  spit(path("zero_dir.rays"), b);
  expect_error(path("zero_dir.rays"), "ray 1: zero direction", [&] { read_rays(path("zero_dir.rays")); });
  // A denormal direction (0, 0, -1e-45): the structures disagreed, a miss in some, a hit at t = inf in others.
  poke_f32(b, ray1 + 24, -1e-45f);
  spit(path("tiny_dir.rays"), b);
  expect_error(path("tiny_dir.rays"),
               "ray 1: direction (0, 0, -1.4013e-45) is shorter than 1e-30: distances along it overflow float",
               [&] { read_rays(path("tiny_dir.rays")); });
  poke_f32(b, ray1 + 24, -1e-29f);  // short, but its distances stay finite: taken
  spit(path("short_dir.rays"), b);
  EXPECT_EQ(read_rays(path("short_dir.rays")).size(), 3u);
}

TEST_F(RayFileTest, InvalidHitsAndOcclusion) {
  std::vector<Hit> hits(2);
  hits[0].prim = 3;
  hits[0].t = 1.0f;
  write_hits(path("h.hits"), std::span<const Hit>(hits));
  std::vector<std::uint8_t> b = slurp(path("h.hits"));
  poke_f32(b, 16 + 8 + 4, 2.0f);  // miss id with a finite t
  spit(path("half.hits"), b);
  expect_error(path("half.hits"), "hit 1:", [&] { read_hits(path("half.hits")); });
  write_occlusion(path("o.occl"), std::vector<std::uint8_t>{0, 1});
  b = slurp(path("o.occl"));
  b[17] = 7;
  spit(path("o.occl"), b);
  expect_error(path("o.occl"), "record 1: value 7", [&] { read_occlusion(path("o.occl")); });
}
}  // namespace unity_test_ray_file
