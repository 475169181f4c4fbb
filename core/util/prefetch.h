#pragma once
// Starting the fetch of an object read at random (a gather) before it is
// needed.
#include <cstddef>

namespace accelviz {

/// Prefetches every cache line `*p` spans (its first byte, every 64 bytes
/// on, and its last byte: an object that is not line-aligned can straddle
/// one more line than its size suggests).
template <class T>
[[gnu::always_inline]] inline void prefetch_object(const T* p) {
  const char* const c = reinterpret_cast<const char*>(p);
  for (std::size_t off = 0; off < sizeof(T); off += 64) __builtin_prefetch(c + off);
  __builtin_prefetch(c + sizeof(T) - 1);
}

}  // namespace accelviz
