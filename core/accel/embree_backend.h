#pragma once
// Intel Embree 3 as a reference backend: the industry's tuned CPU ray tracer,
// to quote our structures' build and query speed against, and its generic
// BVH builder (rtcBuildBVH) to quote our BVH's SAH cost against.
//
// Built only with ACCELVIZ_HAVE_EMBREE (CMake option ACCELVIZ_WITH_EMBREE and
// Debian's libembree-dev); no Embree header leaks out of this file pair.
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string_view>

#include "core/accel/accel.h"

namespace accelviz {

/// True when this build includes the Embree backend.
#ifdef ACCELVIZ_HAVE_EMBREE
inline constexpr bool kHaveEmbree = true;
#else
inline constexpr bool kHaveEmbree = false;
#endif

/// Embree's build quality (RTC_BUILD_QUALITY_*): low = Morton-code build,
/// medium = binned SAH (Embree's default), high = SAH with spatial splits.
enum class EmbreeQuality { low, medium, high };

std::string_view embree_quality_name(EmbreeQuality q);
std::optional<EmbreeQuality> parse_embree_quality(std::string_view name);

/// The instruction set whose kernels Embree may use ("max_isa=" in its
/// device config): automatic = Embree's own choice (the widest the CPU has,
/// e.g. AVX-512, where our fast path stops at AVX2); the others pin it, so
/// its figures can be quoted beside ours on the same ISA. On a CPU without
/// the ISA the accelerator's constructor throws a one-line error.
enum class EmbreeIsa { automatic, sse2, sse42, avx, avx2, avx512 };

/// Every EmbreeIsa, in the enum's order (the CLI's and the settings' choices).
inline constexpr EmbreeIsa kEmbreeIsas[] = {EmbreeIsa::automatic, EmbreeIsa::sse2, EmbreeIsa::sse42,
                                            EmbreeIsa::avx,       EmbreeIsa::avx2, EmbreeIsa::avx512};

/// "auto", "sse2", "sse4.2", "avx", "avx2", "avx512".
std::string_view embree_isa_name(EmbreeIsa isa);
std::optional<EmbreeIsa> parse_embree_isa(std::string_view name);

struct EmbreeOptions {
  EmbreeQuality quality = EmbreeQuality::medium;  ///< scene and geometry build quality
  bool robust = false;   ///< RTC_SCENE_FLAG_ROBUST: avoid optimisations that lose watertightness (slower)
  unsigned threads = 0;  ///< Embree's build threads ("threads=N" device config); 0: Embree's default (all)
  EmbreeIsa isa = EmbreeIsa::automatic;  ///< the kernels Embree may use ("max_isa=" device config)
};

#ifdef ACCELVIZ_HAVE_EMBREE

/// The Embree this program was built against ("3.13.5", RTC_VERSION_STRING).
std::string_view embree_version();

/// Whether this CPU has what Embree's kernels for `isa` use (its AVX2
/// kernels also use FMA, BMI1/2 and LZCNT; its AVX-512 ones AVX-512 F, CD,
/// DQ, BW and VL). Always true for automatic.
bool embree_cpu_has(EmbreeIsa isa);

/// One Embree scene holding one triangle geometry with every triangle in
/// scene order, so Embree's primID is our primitive id. Embree keeps no
/// per-ray counters: RayStats stay zero and VisitTrace stays empty.
/// build_stats() has build_ms (scene creation to commit) and memory_bytes
/// (what Embree allocated, through its memory monitor, plus the vertex and
/// index buffers it shares with us); node counts and SAH are not exposed by
/// Embree and stay 0.
class EmbreeAccelerator final : public Accelerator {
 public:
  /// Throws std::runtime_error ("embree: ...") when Embree reports an error,
  /// and when a triangle has a vertex coordinate beyond ±1.844e18, which
  /// Embree's build would silently leave out (the other structures keep it).
  /// PROGRESS (may be empty) hears Embree's own build progress (its scene progress monitor, calls
  /// serialised); false cancels the build: BuildCancelled.
  EmbreeAccelerator(std::span<const Triangle> triangles, const EmbreeOptions& opts = {},
                    const ProgressCallback& progress = {});
  ~EmbreeAccelerator() override;
  EmbreeAccelerator(const EmbreeAccelerator&) = delete;
  EmbreeAccelerator& operator=(const EmbreeAccelerator&) = delete;

  std::string name() const override { return "embree"; }
  /// Embree's kernels assert on (and, without assertions, mistrace) a ray
  /// with tmin < 0 or NaN, a NaN tmax, or an origin or direction component
  /// that is NaN or beyond ±1.844e18 (Embree's FLT_LARGE): those are refused
  /// (the queries throw std::invalid_argument "embree: ..."), never traced.
  std::string ray_problem(const Ray& ray) const override;
  bool inspectable() const override { return false; }
  Hit closest_hit(const Ray& ray, const QueryOptions& opts, RayStats* stats = nullptr,
                  VisitTrace* trace = nullptr) const override;
  bool any_hit(const Ray& ray, const QueryOptions& opts, RayStats* stats = nullptr) const override;
  const BuildStats& build_stats() const override { return stats_; }
  /// rtcIntersect8/rtcOccluded8 where this Embree build traces packets of
  /// eight natively (RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED).
  bool has_packets() const override;

 protected:
  void closest_packets_span(std::span<const Ray> rays, std::span<Hit> hits, const QueryOptions& opts) const override;
  void any_packets_span(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                        const QueryOptions& opts) const override;

 private:
  /// Our unit normal of triangle `prim` (as closest_hit reports it).
  glm::vec3 normal_of(std::uint32_t prim) const;

  struct Impl;
  std::unique_ptr<Impl> impl_;
  BuildStats stats_;
};

/// A binary BVH built by Embree's own builder (rtcBuildBVH, medium quality:
/// binned SAH; maxBranchingFactor 2), flattened into our node layout and
/// measured with our SAH formula (core/analysis/sah.h), so that our BVH's
/// SAH cost can be quoted against Embree's under identical rules.
struct EmbreeBvhFigures {
  double sah_cost = 0.0;  ///< Σ_inner C_trav·A/A_root + Σ_leaf C_isect·N·A/A_root
  double build_ms = 0.0;  ///< primitive bounds + rtcBuildBVH
  std::uint64_t node_count = 0;
  std::uint64_t leaf_count = 0;
  std::uint32_t max_depth = 0;
  double avg_leaf_depth = 0.0;
};

/// Builds with the same leaf rules as our BvhOptions: a node with at most
/// `min_leaf` primitives is always a leaf (our max_leaf_size, Embree's
/// minLeafSize), one with more than `max_leaf` is always split (our
/// leaf_size_cap, Embree's maxLeafSize, at most 32), between the two the SAH
/// decides. Throws std::runtime_error when Embree fails.
EmbreeBvhFigures embree_binary_bvh_sah(std::span<const Triangle> triangles, float c_trav, float c_isect,
                                       unsigned threads, int min_leaf = 4, int max_leaf = 16);

#endif  // ACCELVIZ_HAVE_EMBREE

}  // namespace accelviz
