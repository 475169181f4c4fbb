#pragma once
// Binary ray and result files (layouts in docs/file-formats-rays.md). All
// little-endian, a 16-byte header: 4 ASCII magic bytes, uint32 version (1),
// uint64 record count, then `count` fixed-size records:
//   RAYS  32 bytes: float32 ox oy oz tmin dx dy dz tmax (tmax 1e30 = unbounded)
//   HITS   8 bytes: uint32 primitive id (0xFFFFFFFF = miss), float32 t (1e30 = miss)
//   OCCL   1 byte : uint8 1 when anything lies in [tmin, tmax], else 0
// Readers check everything before trusting it and report the first problem
// as one line "<file>: <problem>"; nothing is allocated before the count has
// been checked against the file's length.
#include "core/geometry/hit.h"
#include "core/math/ray.h"

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace accelviz {

/// A ray file's direction needs a component of at least this magnitude:
/// distances along a shorter one overflow float (t = distance / length).
inline constexpr float kMinRayDirection = 1e-30f;

/// Every ray-file error; the message is one line, "<file>: <problem>".
class RayFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline constexpr std::uint32_t kRayFileVersion = 1;
inline constexpr std::size_t kRayFileHeaderBytes = 16;
inline constexpr std::size_t kRayRecordBytes = 32;
inline constexpr std::size_t kHitRecordBytes = 8;
inline constexpr std::size_t kOcclusionRecordBytes = 1;

/// One HITS record as stored: the primitive id and t, nothing else.
struct HitRecord {
  std::uint32_t prim = kInvalidId;
  float t = kInfinity;  ///< kInfinity for a miss (1e30 in the file)

  bool valid() const { return prim != kInvalidId; }
  friend bool operator==(const HitRecord&, const HitRecord&) = default;
};

/// Reads a RAYS file. Rejects: a file shorter than the header, a wrong magic or
/// version, a count that disagrees with the file length, a non-finite origin
/// or direction, a zero direction, a NaN tmin/tmax, tmin > tmax.
/// tmax >= 1e30 becomes kInfinity.
std::vector<Ray> read_rays(const std::string& path);

/// Reads a HITS file. Rejects what read_rays rejects at the header level, a NaN
/// t, and a record that is half a miss (id 0xFFFFFFFF with t != 1e30 or the converse).
std::vector<HitRecord> read_hits(const std::string& path);

/// Reads an OCCL file. Rejects a byte other than 0 or 1.
std::vector<std::uint8_t> read_occlusion(const std::string& path);

/// Writers. Refuse (RayFileError "<file>: exists (use --force to overwrite)")
/// when the file exists and `overwrite` is false; the existence check and the
/// creation are one atomic step. An unbounded tmax / a miss t is written as 1e30.
void write_rays(const std::string& path, std::span<const Ray> rays, bool overwrite = false);
void write_hits(const std::string& path, std::span<const Hit> hits, bool overwrite = false);
void write_hits(const std::string& path, std::span<const HitRecord> hits, bool overwrite = false);
void write_occlusion(const std::string& path, std::span<const std::uint8_t> occluded, bool overwrite = false);

}  // namespace accelviz
