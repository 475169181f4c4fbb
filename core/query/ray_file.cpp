#include "core/query/ray_file.h"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/util/file_checks.h"
#include "core/util/output_file.h"

namespace accelviz {

namespace {

// ---- little-endian encoding, independent of the host's byte order ----------

void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
void put_u64(std::vector<std::uint8_t>& out, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
void put_f32(std::vector<std::uint8_t>& out, float v) { put_u32(out, std::bit_cast<std::uint32_t>(v)); }

std::uint32_t get_u32(const std::uint8_t* p) {
  return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
}
std::uint64_t get_u64(const std::uint8_t* p) { return std::uint64_t(get_u32(p)) | std::uint64_t(get_u32(p + 4)) << 32; }
float get_f32(const std::uint8_t* p) { return std::bit_cast<float>(get_u32(p)); }

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw RayFileError(path + ": " + problem);
}

/// Maps "unbounded" to and from the file's 1e30.
float to_file_t(float t) { return t >= kRayFileUnbounded ? kRayFileUnbounded : t; }
float from_file_t(float t) { return t >= kRayFileUnbounded ? kInfinity : t; }

std::string printable_magic(const std::uint8_t* m) {
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>(m[i]);
    if (c >= 0x20 && c < 0x7f) {
      s += c;
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", m[i]);
      s += buf;
    }
  }
  return s;
}

/// Reads and checks the header, then the whole payload (count × record bytes).
/// The count is compared with the file's length before anything is allocated.
std::vector<std::uint8_t> read_payload(const std::string& path, const char (&magic)[5], std::size_t record_bytes,
                                       std::uint64_t& count, const char* what) {
  std::uintmax_t file_size = 0;
  if (const std::string problem = input_file_problem(path, std::numeric_limits<std::uintmax_t>::max(), file_size);
      !problem.empty())
    fail(path, problem);
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, std::string("cannot open: ") + std::strerror(errno));
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0, std::ios::beg);
  if (size < 0) fail(path, "cannot determine the file size");
  if (static_cast<std::uint64_t>(size) < kRayFileHeaderBytes)
    fail(path, "file too short (" + std::to_string(size) + " bytes; a " + magic + " file starts with a " +
                   std::to_string(kRayFileHeaderBytes) + "-byte header)");
  std::uint8_t header[kRayFileHeaderBytes];
  if (!in.read(reinterpret_cast<char*>(header), sizeof header)) fail(path, "cannot read the header");
  if (std::memcmp(header, magic, 4) != 0)
    fail(path, std::string("not a ") + magic + " file (magic '" + printable_magic(header) + "', expected '" +
                   magic + "')");
  const std::uint32_t version = get_u32(header + 4);
  if (version != kRayFileVersion)
    fail(path, "unsupported version " + std::to_string(version) + " (expected " + std::to_string(kRayFileVersion) +
                   ")");
  count = get_u64(header + 8);
  const std::uint64_t remaining = static_cast<std::uint64_t>(size) - kRayFileHeaderBytes;
  // count × record_bytes == remaining, written so that a huge count cannot overflow.
  if (remaining % record_bytes != 0 || count != remaining / record_bytes)
    fail(path, "header says " + std::to_string(count) + " " + what + " of " + std::to_string(record_bytes) +
                   " bytes but " + std::to_string(remaining) + " bytes follow the header");
  std::vector<std::uint8_t> payload(static_cast<std::size_t>(remaining));
  if (remaining > 0 && !in.read(reinterpret_cast<char*>(payload.data()), static_cast<std::streamsize>(remaining)))
    fail(path, "cannot read " + std::to_string(remaining) + " bytes of records");
  return payload;
}

/// Writes header + payload to `path` (write_output_file: a fresh temporary
/// beside it, then its name; exclusively unless `overwrite`).
void write_file(const std::string& path, const char (&magic)[5], std::uint64_t count,
                const std::vector<std::uint8_t>& payload, bool overwrite) {
  std::string header;
  header.reserve(kRayFileHeaderBytes);
  header.append(magic, 4);
  std::vector<std::uint8_t> fields;
  put_u32(fields, kRayFileVersion);
  put_u64(fields, count);
  header.append(reinterpret_cast<const char*>(fields.data()), fields.size());
  const OutputWrite w = write_output_file(
      path, {header, std::string_view(reinterpret_cast<const char*>(payload.data()), payload.size())}, overwrite);
  if (w.exists) fail(path, "exists (use --force to overwrite)");
  if (!w.ok()) fail(path, w.problem);
}

}  // namespace

std::vector<Ray> read_rays(const std::string& path) {
  std::uint64_t count = 0;
  const std::vector<std::uint8_t> payload = read_payload(path, "RAYS", kRayRecordBytes, count, "rays");
  std::vector<Ray> rays;
  rays.reserve(static_cast<std::size_t>(count));
  for (std::uint64_t i = 0; i < count; ++i) {
    const std::uint8_t* p = payload.data() + i * kRayRecordBytes;
    const glm::vec3 o(get_f32(p), get_f32(p + 4), get_f32(p + 8));
    const float tmin = get_f32(p + 12);
    const glm::vec3 d(get_f32(p + 16), get_f32(p + 20), get_f32(p + 24));
    const float tmax = get_f32(p + 28);
    // Built only for a message: every valid record paid for the string.
    const auto where = [i] { return "ray " + std::to_string(i) + ": "; };
    if (std::isnan(o.x) || std::isnan(o.y) || std::isnan(o.z)) fail(path, where() + "NaN in origin");
    if (std::isnan(d.x) || std::isnan(d.y) || std::isnan(d.z)) fail(path, where() + "NaN in direction");
    if (std::isinf(o.x) || std::isinf(o.y) || std::isinf(o.z)) fail(path, where() + "infinite origin");
    if (std::isinf(d.x) || std::isinf(d.y) || std::isinf(d.z)) fail(path, where() + "infinite direction");
    if (d.x == 0.0f && d.y == 0.0f && d.z == 0.0f) fail(path, where() + "zero direction");
    // Distances along a direction this short overflow float (t = distance / length): the structures
    // disagreed on such a ray, a miss in some and a hit at t = inf in others.
    if (std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)}) < kMinRayDirection) {
      char text[128];
      std::snprintf(text, sizeof text, "direction (%g, %g, %g) is shorter than %g", d.x, d.y, d.z, kMinRayDirection);
      fail(path, where() + text + ": distances along it overflow float");
    }
    if (std::isnan(tmin) || std::isnan(tmax)) fail(path, where() + "NaN in tmin/tmax");
    // Behind the origin the structures disagreed (a hit at t = -1 in some, t = +1 or a miss in others):
    // a ray covers t >= 0 from its origin; a segment behind it is a ray from a point further back.
    if (tmin < 0.0f) {
      char text[160];
      std::snprintf(text, sizeof text, "tmin %g is negative (rays start at their origin: move the origin back instead)",
                    static_cast<double>(tmin));
      fail(path, where() + text);
    }
    if (tmin > tmax) fail(path, where() + "tmin > tmax (" + std::to_string(tmin) + " > " + std::to_string(tmax) + ")");
    rays.emplace_back(o, d, tmin, from_file_t(tmax));
  }
  return rays;
}

std::vector<HitRecord> read_hits(const std::string& path) {
  std::uint64_t count = 0;
  const std::vector<std::uint8_t> payload = read_payload(path, "HITS", kHitRecordBytes, count, "hits");
  std::vector<HitRecord> hits;
  hits.reserve(static_cast<std::size_t>(count));
  for (std::uint64_t i = 0; i < count; ++i) {
    const std::uint8_t* p = payload.data() + i * kHitRecordBytes;
    HitRecord h{get_u32(p), get_f32(p + 4)};
    const auto where = [i] { return "hit " + std::to_string(i) + ": "; };
    if (std::isnan(h.t)) fail(path, where() + "NaN t");
    const bool miss_t = h.t >= kRayFileUnbounded;
    if (h.valid() == miss_t)
      fail(path,
           where() + (h.valid() ? "a primitive id with the miss t 1e30" : "the miss id 0xFFFFFFFF with a finite t"));
    h.t = from_file_t(h.t);
    hits.push_back(h);
  }
  return hits;
}

std::vector<std::uint8_t> read_occlusion(const std::string& path) {
  std::uint64_t count = 0;
  std::vector<std::uint8_t> payload = read_payload(path, "OCCL", kOcclusionRecordBytes, count, "records");
  for (std::uint64_t i = 0; i < count; ++i)
    if (payload[i] > 1) fail(path, "record " + std::to_string(i) + ": value " + std::to_string(payload[i]) +
                                       " (expected 0 or 1)");
  return payload;
}

void write_rays(const std::string& path, std::span<const Ray> rays, bool overwrite) {
  std::vector<std::uint8_t> payload;
  payload.reserve(rays.size() * kRayRecordBytes);
  for (const Ray& r : rays) {
    put_f32(payload, r.origin.x);
    put_f32(payload, r.origin.y);
    put_f32(payload, r.origin.z);
    put_f32(payload, r.tmin);
    put_f32(payload, r.direction.x);
    put_f32(payload, r.direction.y);
    put_f32(payload, r.direction.z);
    put_f32(payload, to_file_t(r.tmax));
  }
  write_file(path, "RAYS", rays.size(), payload, overwrite);
}

void write_hits(const std::string& path, std::span<const HitRecord> hits, bool overwrite) {
  std::vector<std::uint8_t> payload;
  payload.reserve(hits.size() * kHitRecordBytes);
  for (std::size_t i = 0; i < hits.size(); ++i) {
    const HitRecord& h = hits[i];
    // 1e30 is the miss's t: a hit there or beyond cannot be told from half a miss.
    if (h.valid() && !(h.t < kRayFileUnbounded)) {
      char t[32];
      std::snprintf(t, sizeof t, "%g", static_cast<double>(h.t));
      fail(path, "hit " + std::to_string(i) + " at t " + t +
                     " cannot be written: 1e30 and beyond is the format's miss value (nothing written)");
    }
    put_u32(payload, h.valid() ? h.prim : kInvalidId);
    put_f32(payload, h.valid() ? h.t : kRayFileUnbounded);
  }
  write_file(path, "HITS", hits.size(), payload, overwrite);
}

void write_hits(const std::string& path, std::span<const Hit> hits, bool overwrite) {
  std::vector<HitRecord> records;
  records.reserve(hits.size());
  for (const Hit& h : hits) records.push_back({h.prim, h.t});
  write_hits(path, std::span<const HitRecord>(records), overwrite);
}

void write_occlusion(const std::string& path, std::span<const std::uint8_t> occluded, bool overwrite) {
  std::vector<std::uint8_t> payload;
  payload.reserve(occluded.size());
  for (std::uint8_t o : occluded) payload.push_back(o ? 1 : 0);
  write_file(path, "OCCL", occluded.size(), payload, overwrite);
}

}  // namespace accelviz
