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
#include <cstddef>
#include <cstdlib>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace accelviz {

inline constexpr std::size_t kHugePageBytes = std::size_t{2} << 20;

template <class T>
struct HugePageAllocator {
  using value_type = T;

  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

  static bool huge(std::size_t n) { return n * sizeof(T) >= kHugePageBytes; }

  T* allocate(std::size_t n) {
    if (n > static_cast<std::size_t>(-1) / sizeof(T)) throw std::bad_array_new_length();
    if (!huge(n)) return static_cast<T*>(::operator new (n * sizeof(T), std::align_val_t{alignof(T)}));
    const std::size_t bytes = (n * sizeof(T) + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
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
    std::free(p);
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
