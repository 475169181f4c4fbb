#include "core/accel/embree_backend.h"

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#include <cpuid.h>
#endif

namespace accelviz {

std::string_view embree_quality_name(EmbreeQuality q) {
  switch (q) {
    case EmbreeQuality::low:
      return "low";
    case EmbreeQuality::medium:
      return "medium";
    case EmbreeQuality::high:
      return "high";
  }
  return "medium";
}

std::optional<EmbreeQuality> parse_embree_quality(std::string_view name) {
  for (EmbreeQuality q : {EmbreeQuality::low, EmbreeQuality::medium, EmbreeQuality::high})
    if (embree_quality_name(q) == name) return q;
  return std::nullopt;
}

std::string_view embree_isa_name(EmbreeIsa isa) {
  switch (isa) {
    case EmbreeIsa::automatic:
      return "auto";
    case EmbreeIsa::sse2:
      return "sse2";
    case EmbreeIsa::sse42:
      return "sse4.2";
    case EmbreeIsa::avx:
      return "avx";
    case EmbreeIsa::avx2:
      return "avx2";
    case EmbreeIsa::avx512:
      return "avx512";
  }
  return "auto";
}

std::optional<EmbreeIsa> parse_embree_isa(std::string_view name) {
  for (EmbreeIsa isa : kEmbreeIsas)
    if (embree_isa_name(isa) == name) return isa;
  return std::nullopt;
}

}  // namespace accelviz

#ifdef ACCELVIZ_HAVE_EMBREE

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/analysis/sah.h"
#include "core/util/timing.h"

namespace accelviz {

namespace {

using Clock = std::chrono::steady_clock;

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
// LZCNT (CPUID 0x80000001, ECX bit 5; AMD calls it ABM). GCC's
// __builtin_cpu_supports knows "lzcnt", clang 14's does not, so ask CPUID.
bool cpu_has_lzcnt() {
  unsigned a = 0, b = 0, c = 0, d = 0;
  return __get_cpuid(0x80000001u, &a, &b, &c, &d) != 0 && (c & (1u << 5)) != 0;
}
#endif

}  // namespace

std::string_view embree_version() {
  return RTC_VERSION_STRING;
}

bool embree_cpu_has(EmbreeIsa isa) {
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
  __builtin_cpu_init();
  switch (isa) {
    case EmbreeIsa::automatic:
      return true;
    case EmbreeIsa::sse2:
      return __builtin_cpu_supports("sse2");
    case EmbreeIsa::sse42:
      return __builtin_cpu_supports("sse4.2");
    case EmbreeIsa::avx:
      return __builtin_cpu_supports("avx");
    case EmbreeIsa::avx2:
      return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi") &&
             __builtin_cpu_supports("bmi2") && cpu_has_lzcnt();
    case EmbreeIsa::avx512:
      return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512cd") &&
             __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw") &&
             __builtin_cpu_supports("avx512vl");
  }
  return false;
#else
  return isa == EmbreeIsa::automatic;  // not an x86 CPU: only Embree's own choice
#endif
}

namespace {

/// A device with an error callback that keeps the first message, and a
/// memory monitor that tracks what Embree holds. Released on destruction.
class Device {
 public:
  Device(unsigned threads, EmbreeIsa isa) {
    // Embree's device config: comma-separated "key=value" items. "max_isa"
    // caps Embree's kernels (and its builder's) at the ISA, within what the
    // CPU has; "isa" would enable the ISA whatever the CPU has (an illegal
    // instruction later), so a CPU without it is refused here first.
    if (!embree_cpu_has(isa))
      throw std::runtime_error("embree: kernels '" + std::string(embree_isa_name(isa)) +
                               "' requested, but this CPU lacks that instruction set");
    std::string config = threads > 0 ? "threads=" + std::to_string(threads) : std::string();
    if (isa != EmbreeIsa::automatic)
      config += (config.empty() ? "max_isa=" : ",max_isa=") + std::string(embree_isa_name(isa));
    device_ = rtcNewDevice(config.empty() ? nullptr : config.c_str());
    if (!device_)
      throw std::runtime_error("embree: cannot create a device (" + error_name(rtcGetDeviceError(nullptr)) + ")");
    rtcSetDeviceErrorFunction(device_, &Device::on_error, this);
    rtcSetDeviceMemoryMonitorFunction(device_, &Device::on_memory, this);
  }
  ~Device() {
    if (device_) rtcReleaseDevice(device_);
  }
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;

  RTCDevice get() const { return device_; }
  std::int64_t bytes() const { return bytes_.load(); }

  /// Forgets a reported error (a build cancelled on purpose).
  void clear() {
    rtcGetDeviceError(device_);
    std::lock_guard lock(mutex_);
    message_.clear();
  }

  /// Throws with Embree's own message when an error was reported.
  void check(const char* step) {
    const RTCError code = rtcGetDeviceError(device_);
    std::lock_guard lock(mutex_);
    if (code != RTC_ERROR_NONE || !message_.empty()) {
      const std::string msg = message_.empty() ? error_name(code) : message_;
      message_.clear();
      throw std::runtime_error(std::string("embree: ") + step + ": " + msg);
    }
  }

 private:
  static std::string error_name(RTCError code) {
    switch (code) {
      case RTC_ERROR_NONE:
        return "no error";
      case RTC_ERROR_INVALID_ARGUMENT:
        return "invalid argument";
      case RTC_ERROR_INVALID_OPERATION:
        return "invalid operation";
      case RTC_ERROR_OUT_OF_MEMORY:
        return "out of memory";
      case RTC_ERROR_UNSUPPORTED_CPU:
        return "unsupported CPU";
      case RTC_ERROR_CANCELLED:
        return "cancelled";
      default:
        return "unknown error";
    }
  }
  static void on_error(void* user, RTCError code, const char* str) {
    auto* self = static_cast<Device*>(user);
    std::lock_guard lock(self->mutex_);
    if (self->message_.empty()) self->message_ = str && *str ? str : error_name(code);
  }
  static bool on_memory(void* user, ssize_t bytes, bool /*post*/) {
    static_cast<Device*>(user)->bytes_.fetch_add(bytes, std::memory_order_relaxed);
    return true;  // never refuse an allocation
  }

  RTCDevice device_ = nullptr;
  std::atomic<std::int64_t> bytes_{0};
  std::mutex mutex_;
  std::string message_;
};

RTCBuildQuality to_rtc(EmbreeQuality q) {
  switch (q) {
    case EmbreeQuality::low:
      return RTC_BUILD_QUALITY_LOW;
    case EmbreeQuality::medium:
      return RTC_BUILD_QUALITY_MEDIUM;
    case EmbreeQuality::high:
      return RTC_BUILD_QUALITY_HIGH;
  }
  return RTC_BUILD_QUALITY_MEDIUM;
}

}  // namespace

// ---- the accelerator ---------------------------------------------------------------

/// Embree's box tests take 1/d with |d| clamped to at least 1e-18 (its
/// rcp_safe), so a direction whose every component is that small is traced
/// with other boxes than its own and misses what it hits: measured on the
/// teapot, rays at distance ~6 lost hits once their largest component fell
/// to ~1e-17 (all of them from ~1e-19 on). 1e-15 keeps a margin; a zero
/// direction is refused too (it can hit nothing).
constexpr float kEmbreeShortest = 1e-15f;

/// The other end of the float range for the same products (overflow: kEmbreeProductLimit below):
/// below about 1e-38 (FLT_MIN) they are denormal and lose their digits, then 0. Measured with
/// `verify -s brute,embree` on a 4×4-per-face cube of half-size s (edges s/2; rays of the scene's
/// size): s = 1e-10 agrees (|e|²·extent = 5e-31), s = 1e-12 mismatched 4 of 5000 rays and s = 1e-14
/// 418 (5e-37, 5e-43). A scene whose largest edge component e and extent give e²·extent below
/// this limit is refused.
constexpr double kEmbreeProductFloor = 1e-33;
/// A ray whose largest direction component d gives e²·d below this is refused (it bites only where
/// the edges are tiny and the scene is not): rays of 3e-15 into a 3e-11 cube, e²·d = 6.7e-37, all
/// agreed with brute force (`trace`, 3,000 rays); products from 1e-37 keep float's full precision.
constexpr double kEmbreeDirectionFloor = 1e-37;

/// How far the scene reaches, for the overflow check of Embree's float
/// triangle test (products_fit_embree), and how short a direction it takes
/// before the test's products fall below float's normal range.
struct EmbreeReach {
  double coordinate = 0.0;  ///< the largest |vertex component|
  double edge = 0.0;        ///< the largest |component| of a triangle edge
  double extent = 0.0;      ///< the scene box's largest side
  // products_fit_embree's bounds on a ray's largest origin (o) and
  // direction (d) components, from the two above (set by limit()).
  float o_max = std::numeric_limits<float>::infinity();   ///< o <= it: |C|·|e|² fits
  float d_max = std::numeric_limits<float>::infinity();   ///< d <= it: |e|²·|D| fits
  float od_max = std::numeric_limits<float>::infinity();  ///< (o + coordinate)·d <= it: |C|·|e|·|D| fits
  float coordinate_f = 0.0f;
  /// A ray's largest direction component must be at least this: kEmbreeShortest, or more where
  /// |e|²·d would fall below kEmbreeDirectionFloor.
  float d_min = kEmbreeShortest;
  void limit(double product_limit) {
    coordinate_f = static_cast<float>(coordinate);
    if (!(edge > 0.0)) return;  // no edge: no product to overflow
    const auto to_float = [](double x) {
      return x >= std::numeric_limits<float>::max() ? std::numeric_limits<float>::infinity() : static_cast<float>(x);
    };
    o_max = to_float(product_limit / (edge * edge) - coordinate);
    d_max = to_float(product_limit / (edge * edge));
    od_max = to_float(product_limit / edge);
    d_min = std::max(kEmbreeShortest, to_float(kEmbreeDirectionFloor / (edge * edge)));
  }
  /// Whether the scene is too small for the test: |e|²·extent below kEmbreeProductFloor (a scene
  /// without an edge has nothing to hit and is never too small).
  bool too_small() const { return edge > 0.0 && edge * edge * extent < kEmbreeProductFloor; }
};

struct EmbreeAccelerator::Impl {
  Impl(unsigned threads, EmbreeIsa isa) : device(threads, isa) {}
  ~Impl() {
    if (scene) rtcReleaseScene(scene);
  }

  Device device;
  RTCScene scene = nullptr;
  // Embree reads vertex buffers with 16-byte loads: one spare float3 at the
  // end keeps the last vertex's load inside our allocation.
  std::vector<float> vertices;         ///< 3 per triangle corner, plus one padding vertex
  std::vector<std::uint32_t> indices;  ///< 0, 1, 2, ...: triangle i uses corners 3i..3i+2
  EmbreeReach reach;
};

namespace {

/// Embree's FLT_LARGE: "we consider floating point numbers in that range as
/// valid input numbers" (its kernels' Ray::valid; its builders leave out a
/// primitive with a coordinate beyond it).
constexpr float kEmbreeLarge = 1.844e18f;

bool within_embree_range(const glm::vec3& v) {
  return std::abs(v.x) <= kEmbreeLarge && std::abs(v.y) <= kEmbreeLarge && std::abs(v.z) <= kEmbreeLarge;
}

float largest_component(const glm::vec3& d) {
  return std::max(std::abs(d.x), std::max(std::abs(d.y), std::abs(d.z)));
}

/// At least kEmbreeShortest, and long enough for the scene's products (EmbreeReach::d_min).
bool long_enough_for_embree(const glm::vec3& d, const EmbreeReach& reach) {
  return largest_component(d) >= reach.d_min;
}

/// Embree's triangle tests work in float on C = v0 - o, the edges, their
/// cross product and the direction D (default mode: T = Ng·C, U = (C×D)·e2,
/// den = Ng·D; robust mode alike, on sums of two vertices), so a triple
/// product beyond FLT_MAX becomes inf and the hit is lost: measured on a
/// 4×4-per-face cube of half-size s with `verify -s brute,embree` (rays of
/// the scene's size), agreement up to s = 1e12 and 1854 of 5000 rays
/// mismatched at 1e13. With x, y, z the largest |component| of three
/// vectors, a component of x×y is at most 2xy and a dot product with z at
/// most 3 of those: 6xyz, 12xyz with the robust mode's sums. Refused when
/// 12 times the largest of |C|·|e|², |C|·|e|·|D| and |e|²·|D| (largest
/// components) passes 3e38 (FLT_MAX is 3.4e38).
constexpr double kEmbreeProductLimit = 3e38 / 12.0;

// With |C| <= o + coordinate and e the scene's edge bound: o + coordinate <=
// limit/e², d <= limit/e² and (o + coordinate)·d <= limit/e, precomputed per
// scene (EmbreeReach::limit), so the check inside the queries is a few float
// operations (rounding is far inside the margin).
[[gnu::always_inline]] inline bool products_fit_embree(const Ray& ray, const EmbreeReach& reach) {
  const float o = largest_component(ray.origin), d = largest_component(ray.direction);
  return o <= reach.o_max && d <= reach.d_max && (o + reach.coordinate_f) * d <= reach.od_max;
}

std::string num_text(float x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", x);
  return buf;
}

std::string vec_text(const glm::vec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%g, %g, %g)", v.x, v.y, v.z);
  return buf;
}

/// What the queries throw for a ray Embree cannot take (out of line: the
/// check in the queries is a predictable branch).
[[noreturn, gnu::cold, gnu::noinline]] void refuse_ray(const EmbreeAccelerator& embree, const Ray& ray) {
  throw std::invalid_argument("embree: " + embree.ray_problem(ray));
}

/// Whether Embree takes the ray (ray_problem's test, without the words).
[[gnu::always_inline]] inline bool embree_takes(const Ray& ray, const EmbreeReach& reach) {
  return ray.tmin >= 0.0f && ray.tmax == ray.tmax && within_embree_range(ray.origin) &&
         within_embree_range(ray.direction) && long_enough_for_embree(ray.direction, reach) &&
         products_fit_embree(ray, reach);
}

}  // namespace

std::string EmbreeAccelerator::ray_problem(const Ray& ray) const {
  std::string why;
  if (!(ray.tmin >= 0.0f))
    why = "tmin " + num_text(ray.tmin) + " is not >= 0";
  else if (ray.tmax != ray.tmax)
    why = "tmax is NaN";
  else if (!within_embree_range(ray.origin))
    why = "origin " + vec_text(ray.origin) + " has a component";
  else if (!within_embree_range(ray.direction))
    why = "direction " + vec_text(ray.direction) + " has a component";
  else if (!(largest_component(ray.direction) >= kEmbreeShortest))
    return "cannot trace a ray whose direction " + vec_text(ray.direction) +
           " has no component of 1e-15 or more (Embree clamps 1/d at 1e18 in its box tests and would miss what "
           "the ray hits; accelviz's own structures trace it)";
  else if (!long_enough_for_embree(ray.direction, impl_->reach))
    return "cannot trace a ray whose direction " + vec_text(ray.direction) + " has no component of " +
           num_text(impl_->reach.d_min) + " or more in this scene (edge components up to " +
           num_text(static_cast<float>(impl_->reach.edge)) +
           "): Embree's float triangle test would underflow (products like |e1|·|e2|·|D| below float's normal "
           "range) and miss what the ray hits; accelviz's own structures trace it";
  else if (!products_fit_embree(ray, impl_->reach))
    return "cannot trace a ray from " + vec_text(ray.origin) + " along " + vec_text(ray.direction) +
           " in this scene (vertex coordinates up to " + num_text(static_cast<float>(impl_->reach.coordinate)) +
           ", edge components up to " + num_text(static_cast<float>(impl_->reach.edge)) +
           "): Embree's float triangle test would overflow (products like |v0 - o|·|e1|·|e2| near FLT_MAX) and miss "
           "what the ray hits; accelviz's own structures trace it";
  else
    return {};
  if (why.ends_with("component")) why += " that is NaN or beyond ±1.844e18";
  return "cannot trace a ray whose " + why +
         " (Embree's kernels assume 0 <= tmin and finite origins and directions within ±1.844e18; "
         "accelviz's own structures trace it)";
}

EmbreeAccelerator::EmbreeAccelerator(std::span<const Triangle> triangles, const EmbreeOptions& opts,
                                     const ProgressCallback& progress)
    : impl_(std::make_unique<Impl>(opts.threads, opts.isa)) {
  // Our checks first, outside Embree's build time.
  const std::size_t n = triangles.size();
  std::size_t out_of_range = 0, first_out = 0;
  EmbreeReach& reach = impl_->reach;
  glm::dvec3 box_lo(std::numeric_limits<double>::infinity()), box_hi(-std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < n; ++i) {
    const Triangle& t = triangles[i];
    if (!within_embree_range(t.v0) || !within_embree_range(t.v1) || !within_embree_range(t.v2)) {
      if (out_of_range++ == 0) first_out = i;
      continue;
    }
    for (const glm::vec3* v : {&t.v0, &t.v1, &t.v2})
      for (int a = 0; a < 3; ++a) reach.coordinate = std::max(reach.coordinate, std::abs(static_cast<double>((*v)[a])));
    const glm::dvec3 a(t.v0), b(t.v1), c(t.v2);
    for (const glm::dvec3& edge : {b - a, c - b, a - c})
      reach.edge = std::max({reach.edge, std::abs(edge.x), std::abs(edge.y), std::abs(edge.z)});
    box_lo = glm::min(box_lo, glm::min(a, glm::min(b, c)));
    box_hi = glm::max(box_hi, glm::max(a, glm::max(b, c)));
  }
  if (box_lo.x <= box_hi.x) {
    const glm::dvec3 side = box_hi - box_lo;
    reach.extent = std::max({side.x, side.y, side.z});
  }
  reach.limit(kEmbreeProductLimit);
  if (out_of_range > 0)
    throw std::runtime_error(
        "embree: " +
        (out_of_range == 1 ? "triangle " + std::to_string(first_out) + " has"
                           : std::to_string(out_of_range) + " triangles (the first: triangle " +
                                 std::to_string(first_out) + ") have") +
        " a vertex coordinate beyond ±1.844e18, which Embree's build leaves out; accelviz's own structures "
        "(bvh, kdtree, grid, ...) keep them");
  if (reach.too_small())
    throw std::runtime_error(
        "embree: the scene is too small for Embree's float triangle test (extent " +
        num_text(static_cast<float>(reach.extent)) + ", edge components up to " +
        num_text(static_cast<float>(reach.edge)) +
        "): its products (|e1|·|e2|·|v0 - o| about edge²·extent) fall below float's normal range and it would "
        "miss what rays hit; accelviz's own structures (bvh, kdtree, grid, ...) trace it");
  const auto t0 = Clock::now();
  impl_->vertices.resize(9 * n + 3, 0.0f);
  impl_->indices.resize(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3* v[3] = {&triangles[i].v0, &triangles[i].v1, &triangles[i].v2};
    for (int k = 0; k < 3; ++k) {
      impl_->vertices[9 * i + 3 * k + 0] = v[k]->x;
      impl_->vertices[9 * i + 3 * k + 1] = v[k]->y;
      impl_->vertices[9 * i + 3 * k + 2] = v[k]->z;
      impl_->indices[3 * i + k] = static_cast<std::uint32_t>(3 * i + k);
    }
  }

  Device& dev = impl_->device;
  impl_->scene = rtcNewScene(dev.get());
  dev.check("rtcNewScene");
  rtcSetSceneFlags(impl_->scene, opts.robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
  rtcSetSceneBuildQuality(impl_->scene, to_rtc(opts.quality));
  if (n > 0) {
    RTCGeometry geom = rtcNewGeometry(dev.get(), RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(geom, to_rtc(opts.quality));
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, impl_->vertices.data(), 0,
                               3 * sizeof(float), 3 * n);
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, impl_->indices.data(), 0,
                               3 * sizeof(std::uint32_t), n);
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(impl_->scene, geom, 0);  // geomID 0: the one geometry
    rtcReleaseGeometry(geom);
    dev.check("triangle geometry");
  }
  // Embree's progress, forwarded; false cancels the build, which then reports RTC_ERROR_CANCELLED.
  // Its build threads call the monitor often and at once: only a new whole percent reaches
  // `progress` (at most 101 calls, one thread at a time; a thread that finds another reporting
  // goes on), so the build is not held up by it (bench times Embree's build with it).
  struct Monitor {
    const ProgressCallback* progress;
    std::mutex mutex;
    std::atomic<bool> cancelled{false};
    std::atomic<int> reported{0};  ///< the last whole percent passed on (0 was, before the build)
    static bool call(void* ptr, double fraction) {
      auto* m = static_cast<Monitor*>(ptr);
      if (m->cancelled.load(std::memory_order_relaxed)) return false;
      const int percent = static_cast<int>(std::clamp(fraction, 0.0, 1.0) * 100.0);
      if (percent <= m->reported.load(std::memory_order_relaxed)) return true;
      std::unique_lock lock(m->mutex, std::try_to_lock);
      if (!lock.owns_lock() || percent <= m->reported.load(std::memory_order_relaxed)) return true;
      m->reported.store(percent, std::memory_order_relaxed);
      if (!(*m->progress)(percent / 100.0)) m->cancelled.store(true, std::memory_order_relaxed);
      return !m->cancelled.load(std::memory_order_relaxed);
    }
  } monitor{&progress};
  if (progress) {
    if (!progress(0.0)) throw BuildCancelled();
    rtcSetSceneProgressMonitorFunction(impl_->scene, &Monitor::call, &monitor);
  }
  rtcCommitScene(impl_->scene);
  if (progress) rtcSetSceneProgressMonitorFunction(impl_->scene, nullptr, nullptr);
  if (monitor.cancelled.load()) {
    dev.clear();
    throw BuildCancelled();
  }
  dev.check("rtcCommitScene");
  if (progress) progress(1.0);

  stats_.build_ms = ms_since(t0);
  stats_.memory_bytes = static_cast<std::uint64_t>(std::max<std::int64_t>(0, dev.bytes())) +
                        impl_->vertices.size() * sizeof(float) + impl_->indices.size() * sizeof(std::uint32_t);
}

EmbreeAccelerator::~EmbreeAccelerator() = default;

namespace {

void fill_ray(RTCRay& r, const Ray& ray) {
  r.org_x = ray.origin.x;
  r.org_y = ray.origin.y;
  r.org_z = ray.origin.z;
  r.tnear = ray.tmin;
  r.dir_x = ray.direction.x;
  r.dir_y = ray.direction.y;
  r.dir_z = ray.direction.z;
  r.time = 0.0f;
  r.tfar = ray.tmax;
  r.mask = 0xFFFFFFFFu;
  r.id = 0;
  r.flags = 0;
}

}  // namespace

Hit EmbreeAccelerator::closest_hit(const Ray& ray, const QueryOptions&, RayStats*, VisitTrace*) const {
  if (!embree_takes(ray, impl_->reach)) [[unlikely]]
    refuse_ray(*this, ray);
  RTCRayHit rh;
  fill_ray(rh.ray, ray);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  rtcIntersect1(impl_->scene, &context, &rh);
  Hit hit;
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return hit;
  hit.prim = rh.hit.primID;
  hit.t = rh.ray.tfar;
  hit.u = rh.hit.u;  // Embree's barycentrics follow the same convention: p = (1-u-v)v0 + u v1 + v v2
  hit.v = rh.hit.v;
  hit.ng = normal_of(hit.prim);
  return hit;
}

glm::vec3 EmbreeAccelerator::normal_of(std::uint32_t prim) const {
  // Our unit normal of (v1-v0)x(v2-v0), the same for every structure (Embree's
  // Ng is unnormalised and of the opposite orientation).
  const float* v = impl_->vertices.data() + 9 * static_cast<std::size_t>(prim);
  return triangle_normal({{v[0], v[1], v[2]}, {v[3], v[4], v[5]}, {v[6], v[7], v[8]}});
}

bool EmbreeAccelerator::has_packets() const {
  return rtcGetDeviceProperty(impl_->device.get(), RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED) != 0;
}

namespace {

/// Lane l of an RTCRay8 from `ray` (fill_ray's fields); valid[l] = -1.
void fill_lane(RTCRay8& r, int l, const Ray& ray) {
  r.org_x[l] = ray.origin.x;
  r.org_y[l] = ray.origin.y;
  r.org_z[l] = ray.origin.z;
  r.tnear[l] = ray.tmin;
  r.dir_x[l] = ray.direction.x;
  r.dir_y[l] = ray.direction.y;
  r.dir_z[l] = ray.direction.z;
  r.time[l] = 0.0f;
  r.tfar[l] = ray.tmax;
  r.mask[l] = 0xFFFFFFFFu;
  r.id[l] = 0;
  r.flags[l] = 0;
}

/// Calls trace(first, count, valid) for each packet of eight consecutive
/// rays of n (the last may be shorter), with Embree's validity mask:
/// valid[l] = -1 for the count lanes that carry a ray, 0 for the others.
template <class Trace>
void for_each_packet8(std::size_t n, Trace&& trace) {
  for (std::size_t first = 0; first < n; first += 8) {
    const int count = static_cast<int>(std::min<std::size_t>(8, n - first));
    alignas(32) int valid[8];
    for (int l = 0; l < 8; ++l) valid[l] = l < count ? -1 : 0;
    trace(first, count, valid);
  }
}

}  // namespace

void EmbreeAccelerator::closest_packets_span(std::span<const Ray> rays, std::span<Hit> hits,
                                             const QueryOptions& opts) const {
  if (!has_packets()) {
    Accelerator::closest_packets_span(rays, hits, opts);
    return;
  }
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  for_each_packet8(rays.size(), [&](std::size_t b, int count, const int* valid) {
    RTCRayHit8 rh;
    for (int l = 0; l < 8; ++l) {
      if (l < count) {
        if (!embree_takes(rays[b + l], impl_->reach)) [[unlikely]]
          refuse_ray(*this, rays[b + l]);
        fill_lane(rh.ray, l, rays[b + l]);
      }
      rh.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.primID[l] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0][l] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect8(valid, impl_->scene, &context, &rh);
    for (int l = 0; l < count; ++l) {
      Hit hit;
      if (rh.hit.geomID[l] != RTC_INVALID_GEOMETRY_ID) {
        hit.prim = rh.hit.primID[l];
        hit.t = rh.ray.tfar[l];
        hit.u = rh.hit.u[l];
        hit.v = rh.hit.v[l];
        hit.ng = normal_of(hit.prim);
      }
      hits[b + l] = hit;
    }
  });
}

void EmbreeAccelerator::any_packets_span(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                                         const QueryOptions& opts) const {
  if (!has_packets()) {
    Accelerator::any_packets_span(rays, occluded, opts);
    return;
  }
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  for_each_packet8(rays.size(), [&](std::size_t b, int count, const int* valid) {
    RTCRay8 r;
    for (int l = 0; l < count; ++l) {
      if (!embree_takes(rays[b + l], impl_->reach)) [[unlikely]]
        refuse_ray(*this, rays[b + l]);
      fill_lane(r, l, rays[b + l]);
    }
    rtcOccluded8(valid, impl_->scene, &context, &r);
    for (int l = 0; l < count; ++l) occluded[b + l] = r.tfar[l] == -kInfinity ? 1 : 0;
  });
}

bool EmbreeAccelerator::any_hit(const Ray& ray, const QueryOptions&, RayStats*) const {
  if (!embree_takes(ray, impl_->reach)) [[unlikely]]
    refuse_ray(*this, ray);
  RTCRay r;
  fill_ray(r, ray);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  rtcOccluded1(impl_->scene, &context, &r);
  return r.tfar == -kInfinity;  // Embree marks an occluded ray by setting tfar to -inf
}

// ---- Embree's binary BVH builder, measured with our SAH ----------------------------

namespace {

/// Nodes the builder's callbacks create, in Embree's thread-local arena (freed
/// with the RTCBVH). `leaf` distinguishes the two kinds behind a void*.
struct BuildNode {
  bool leaf = false;
  std::uint32_t count = 0;  ///< leaf: primitives
  BuildNode* children[2] = {nullptr, nullptr};
  Aabb bounds[2];  ///< inner: the children's boxes
};

void* create_node(RTCThreadLocalAllocator alloc, unsigned int child_count, void*) {
  if (child_count > 2) return nullptr;  // cannot happen with maxBranchingFactor 2
  void* mem = rtcThreadLocalAlloc(alloc, sizeof(BuildNode), alignof(BuildNode));
  return new (mem) BuildNode{};
}

void set_children(void* node, void** children, unsigned int count, void*) {
  auto* n = static_cast<BuildNode*>(node);
  for (unsigned i = 0; i < count && i < 2; ++i) n->children[i] = static_cast<BuildNode*>(children[i]);
}

void set_bounds(void* node, const RTCBounds** bounds, unsigned int count, void*) {
  auto* n = static_cast<BuildNode*>(node);
  for (unsigned i = 0; i < count && i < 2; ++i)
    n->bounds[i] = {{bounds[i]->lower_x, bounds[i]->lower_y, bounds[i]->lower_z},
                    {bounds[i]->upper_x, bounds[i]->upper_y, bounds[i]->upper_z}};
}

void* create_leaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive*, size_t count, void*) {
  void* mem = rtcThreadLocalAlloc(alloc, sizeof(BuildNode), alignof(BuildNode));
  auto* n = new (mem) BuildNode{};
  n->leaf = true;
  n->count = static_cast<std::uint32_t>(count);
  return n;
}

}  // namespace

EmbreeBvhFigures embree_binary_bvh_sah(std::span<const Triangle> triangles, float c_trav, float c_isect,
                                       unsigned threads, int min_leaf, int max_leaf) {
  EmbreeBvhFigures fig;
  if (triangles.empty()) return fig;
  if (min_leaf < 1 || max_leaf < min_leaf || max_leaf > RTC_BUILD_MAX_PRIMITIVES_PER_LEAF)
    throw std::invalid_argument("embree_binary_bvh_sah: need 1 <= min_leaf <= max_leaf <= " +
                                std::to_string(RTC_BUILD_MAX_PRIMITIVES_PER_LEAF));
  Device dev(threads, EmbreeIsa::automatic);  // its generic builder; the SAH does not depend on the ISA
  RTCBVH bvh = rtcNewBVH(dev.get());
  dev.check("rtcNewBVH");
  struct BvhReleaser {
    RTCBVH b;
    ~BvhReleaser() { rtcReleaseBVH(b); }
  } releaser{bvh};

  const auto t0 = Clock::now();
  std::vector<RTCBuildPrimitive> prims(triangles.size());
  Aabb root_bounds;
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    const Aabb b = triangles[i].bounds();
    root_bounds.extend(b);
    prims[i].lower_x = b.lo.x;
    prims[i].lower_y = b.lo.y;
    prims[i].lower_z = b.lo.z;
    prims[i].geomID = 0;
    prims[i].upper_x = b.hi.x;
    prims[i].upper_y = b.hi.y;
    prims[i].upper_z = b.hi.z;
    prims[i].primID = static_cast<unsigned>(i);
  }
  RTCBuildArguments args = rtcDefaultBuildArguments();
  args.buildQuality = RTC_BUILD_QUALITY_MEDIUM;
  args.maxBranchingFactor = 2;
  args.maxDepth = 64;  // our builder's depth limit (kBvhMaxDepth)
  args.sahBlockSize = 1;
  args.minLeafSize = static_cast<unsigned>(min_leaf);
  args.maxLeafSize = static_cast<unsigned>(max_leaf);
  args.traversalCost = c_trav;
  args.intersectionCost = c_isect;
  args.bvh = bvh;
  args.primitives = prims.data();
  args.primitiveCount = prims.size();
  args.primitiveArrayCapacity = prims.size();
  args.createNode = create_node;
  args.setNodeChildren = set_children;
  args.setNodeBounds = set_bounds;
  args.createLeaf = create_leaf;
  auto* root = static_cast<BuildNode*>(rtcBuildBVH(&args));
  fig.build_ms = ms_since(t0);
  dev.check("rtcBuildBVH");
  if (!root) throw std::runtime_error("embree: rtcBuildBVH returned no tree");

  // Flatten into our layout (children adjacent, after their parent) so that the
  // very same SAH and shape functions measure both trees.
  std::vector<BvhNode> nodes;
  nodes.reserve(2 * triangles.size() / static_cast<std::size_t>(min_leaf) + 1);
  nodes.push_back({root_bounds, 0, 0});
  std::vector<std::pair<const BuildNode*, std::uint32_t>> stack{{root, 0u}};
  while (!stack.empty()) {
    const auto [n, slot] = stack.back();
    stack.pop_back();
    if (n->leaf) {
      nodes[slot].index = 0;
      nodes[slot].count = n->count;
      continue;
    }
    const auto first = static_cast<std::uint32_t>(nodes.size());
    nodes[slot].index = first;
    nodes[slot].count = 0;
    for (int k = 0; k < 2; ++k) {
      nodes.push_back({n->bounds[k], 0, 0});
      stack.push_back({n->children[k], first + static_cast<std::uint32_t>(k)});
    }
  }
  fig.sah_cost = bvh_sah_cost(nodes, c_trav, c_isect);
  const TreeShape shape = bvh_tree_shape(nodes);
  fig.node_count = nodes.size();
  fig.leaf_count = shape.leaf_count;
  fig.max_depth = shape.max_depth;
  fig.avg_leaf_depth = shape.avg_leaf_depth;
  return fig;
}

}  // namespace accelviz

#endif  // ACCELVIZ_HAVE_EMBREE
