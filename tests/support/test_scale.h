#pragma once
// How much of their full size the large differential tests run (rays, and
// for some the meshes): ACCELVIZ_VERIFY_SCALE, clamped to [0.01, 1]. The
// sanitizer presets set 0.05 and the scalar-path preset (nosimd) 0.25 in
// CMakePresets.json; without the variable a sanitizer build runs at 0.05
// and every other build at full size (Release CI: the million-ray runs).
// tests/cli/verify_scale.sh scales `accelviz verify` by the same variable.
#include <algorithm>
#include <cstddef>
#include <cstdlib>

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ACCELVIZ_TEST_HAS_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define ACCELVIZ_TEST_HAS_ASAN 1
#endif
#ifndef ACCELVIZ_TEST_HAS_ASAN
#define ACCELVIZ_TEST_HAS_ASAN 0
#endif

namespace accelviz::test_scale {

inline double verify_scale() {
  if (const char* v = std::getenv("ACCELVIZ_VERIFY_SCALE")) return std::clamp(std::atof(v), 0.01, 1.0);
  return ACCELVIZ_TEST_HAS_ASAN ? 0.05 : 1.0;
}

/// `full` scaled by verify_scale(), never below `minimum` (nor above `full`).
inline std::size_t scaled(std::size_t full, std::size_t minimum) {
  const auto n = static_cast<std::size_t>(static_cast<double>(full) * verify_scale());
  return std::min(full, std::max(minimum, n));
}

}  // namespace accelviz::test_scale
