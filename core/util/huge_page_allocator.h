#pragma once
// An allocator for the large arrays a ray walks at random (the wide BVH's
// nodes, its triangle blocks): on Linux, arrays of 2 MiB or more are placed on
// 2 MiB boundaries and marked MADV_HUGEPAGE, so that transparent huge pages
// back them where the system allows it ("madvise" or "always" in
// /sys/kernel/mm/transparent_hugepage/enabled).
//
// Why: a single ray touches a few dozen nodes and triangle blocks spread over
// tens of megabytes. With 4 KiB pages nearly every such access also misses the
// TLB (a 2048-entry second-level TLB covers 8 MiB), and the page walk adds to
// the cache miss. Embree allocates its BVH the same way (os_malloc with
// MADV_HUGEPAGE). Where huge pages are unavailable the memory is ordinary
// memory; the hint changes nothing but speed. Smaller arrays use operator new.
//
// The BVH build puts every large array it writes on them too (build records,
// binary nodes, primitive indices, the wide collapse's scratch): a build writes
// each array once into fresh memory, and on virtual machines the first touch of
// a 4 KiB page is dear. Measured on this project's 2-vCPU AMD EPYC VM
// (2026-12-02): touching 36 MiB took 92-117 ms with 4 KiB pages and 2.4-2.6 ms
// with huge pages, and the dragon's one-thread build fell from ~640 to ~370 ms
// (docs/performance.md, "Page faults").
//
// Freed arrays of 2 to 64 MiB are kept (up to kKeptBytes in all) and handed
// to the next allocation of about their size, so that a rebuild (a slider in
// the GUI, a sweep, a benchmark's loop) writes into pages that are already
// mapped instead of having the kernel map and zero them again: the dragon's
// build spent about a tenth of its time in the kernel's page clearing when
// every build started from fresh memory (docs/performance.md).
#include <array>
#include <cstddef>
#include <cstdlib>
#include <mutex>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace accelviz {

inline constexpr std::size_t kHugePageBytes = std::size_t{2} << 20;

namespace huge_page_detail {

/// Freed huge-page regions kept for reuse, oldest first.
struct KeptRegions {
  static constexpr std::size_t kKeptBytes = std::size_t{512} << 20;       ///< at most this much kept in all
  static constexpr std::size_t kKeptRegionBytes = std::size_t{64} << 20;  ///< larger regions are freed at once
  static constexpr int kSlots = 16;
  std::mutex mutex;
  std::array<void*, kSlots> ptr{};
  std::array<std::size_t, kSlots> bytes{};
  int count = 0;
  std::size_t total = 0;
  /// Regions handed out by take_region with their true size, which can be up
  /// to twice the request's: keep_region records that size when they come
  /// back, so that `total` (and the kKeptBytes budget) counts what is held.
  std::vector<std::pair<void*, std::size_t>> lent;

  void remove(int i) {
    total -= bytes[i];
    for (int j = i + 1; j < count; ++j) {
      ptr[j - 1] = ptr[j];
      bytes[j - 1] = bytes[j];
    }
    --count;
  }
};

/// The process's kept regions. Never destroyed, so that arrays freed during
/// static destruction still find it (the regions stay reachable through it).
inline KeptRegions& kept_regions() {
  static KeptRegions* const kept = new KeptRegions;
  return *kept;
}

/// The smallest kept region of `bytes` to 2 x `bytes`, taken out of the
/// kept set; nullptr if none. Its memory holds whatever its last user wrote.
inline void* take_region(std::size_t bytes) {
  KeptRegions& k = kept_regions();
  const std::lock_guard lock(k.mutex);
  int best = -1;
  for (int i = 0; i < k.count; ++i)
    if (k.bytes[i] >= bytes && k.bytes[i] / 2 <= bytes && (best < 0 || k.bytes[i] < k.bytes[best])) best = i;
  if (best < 0) return nullptr;
  void* const p = k.ptr[best];
  k.lent.emplace_back(p, k.bytes[best]);
  k.remove(best);
  return p;
}

/// Keeps region p (at least `bytes` long) for reuse, freeing the oldest kept
/// regions where the new one would not fit otherwise; frees p itself if it is
/// larger than KeptRegions::kKeptRegionBytes (keeping regions of hundreds of
/// MiB made the 10M-triangle soup's builds about a fifth slower, measured,
/// cause not found; docs/performance.md).
inline void keep_region(void* p, std::size_t bytes) {
  if (bytes > KeptRegions::kKeptRegionBytes) {
    std::free(p);
    return;
  }
  KeptRegions& k = kept_regions();
  void* freed[KeptRegions::kSlots];
  int nfreed = 0;
  {
    const std::lock_guard lock(k.mutex);
    for (std::size_t i = 0; i < k.lent.size(); ++i)
      if (k.lent[i].first == p) {  // a reused region: its true size
        bytes = k.lent[i].second;
        k.lent[i] = k.lent.back();
        k.lent.pop_back();
        break;
      }
    while (k.count == KeptRegions::kSlots || k.total + bytes > KeptRegions::kKeptBytes) {
      freed[nfreed++] = k.ptr[0];
      k.remove(0);
    }
    k.ptr[k.count] = p;
    k.bytes[k.count] = bytes;
    ++k.count;
    k.total += bytes;
  }
  for (int i = 0; i < nfreed; ++i) std::free(freed[i]);
}

/// Bytes kept now.
inline std::size_t kept_bytes() {
  KeptRegions& k = kept_regions();
  const std::lock_guard lock(k.mutex);
  return k.total;
}

/// Frees every kept region (gives their memory back to the system).
inline void release_kept_regions() {
  KeptRegions& k = kept_regions();
  const std::lock_guard lock(k.mutex);
  for (int i = 0; i < k.count; ++i) std::free(k.ptr[i]);
  k.count = 0;
  k.total = 0;
}

}  // namespace huge_page_detail

/// Fixes glibc's malloc thresholds for this process: allocations below 64 MiB
/// come from the heap and freed heap memory is kept up to 256 MiB, so that
/// repeated builds reuse mapped pages. By default glibc maps every allocation
/// of 128 KiB or more afresh (page faults on each build) until a larger block
/// is freed and it raises its threshold: a `sweep`'s first setting then built
/// in about twice the time of the same setting later in the process
/// (docs/accuracy-vs-time.md). Called where builds are compared within a
/// process (the `sweep` command, the app's window); does nothing without glibc.
inline void use_fixed_malloc_thresholds() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 64 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
#endif
}

template <class T>
struct HugePageAllocator {
  using value_type = T;

  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

  static bool huge(std::size_t n) { return n * sizeof(T) >= kHugePageBytes; }
  /// A huge array's region: whole huge pages.
  static std::size_t region_bytes(std::size_t n) {
    return (n * sizeof(T) + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
  }

  T* allocate(std::size_t n) {
    if (n > static_cast<std::size_t>(-1) / sizeof(T)) throw std::bad_array_new_length();
    if (!huge(n)) return static_cast<T*>(::operator new (n * sizeof(T), std::align_val_t{alignof(T)}));
    const std::size_t bytes = region_bytes(n);
    if (void* kept = huge_page_detail::take_region(bytes)) return static_cast<T*>(kept);
    void* p = std::aligned_alloc(kHugePageBytes, bytes);
    if (p == nullptr) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    madvise(p, bytes, MADV_HUGEPAGE);  // a hint: failure leaves ordinary pages
#endif
    return static_cast<T*>(p);
  }

  /// resize() default-initialises (a trivial element is left unwritten, not
  /// zeroed), so the pages are first touched, and faulted in, by whoever fills
  /// them: class Bvh fills its triangle blocks on all build threads.
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }

  void deallocate(T* p, std::size_t n) noexcept {
    if (!huge(n)) {
      ::operator delete (p, std::align_val_t{alignof(T)});
      return;
    }
    huge_page_detail::keep_region(p, region_bytes(n));
  }

  template <class U>
  bool operator==(const HugePageAllocator<U>&) const noexcept {
    return true;
  }
};

/// A std::vector whose storage is HugePageAllocator's.
template <class T>
using HugePageVector = std::vector<T, HugePageAllocator<T>>;

}  // namespace accelviz
