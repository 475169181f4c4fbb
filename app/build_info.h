#pragma once
// What this program was built from, for --version and the machine record of
// measurements (bench, sweep and calibrate JSON): figures can then be traced
// to the commit that produced them. Written at build time by
// app/build_info.cmake.

namespace accelviz::build_info {

extern const char* const kVersion;    ///< the project's version ("0.1.0")
extern const char* const kCommit;     ///< `git describe --always --dirty` of the source tree, or "unknown"
extern const char* const kBuildType;  ///< CMAKE_BUILD_TYPE ("Release", "Debug")

}  // namespace accelviz::build_info
