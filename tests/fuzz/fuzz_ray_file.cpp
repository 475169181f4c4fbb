// libFuzzer target: the binary RAYS / HITS / OCCL readers, all three on every
// input. RayFileError is expected on bad input; anything else is a finding.
#include "core/query/ray_file.h"
#include "tests/fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = accelviz_fuzz::write_input(data, size, "bin");
  try {
    (void)accelviz::read_rays(path);
  } catch (const accelviz::RayFileError&) {
  }
  try {
    (void)accelviz::read_hits(path);
  } catch (const accelviz::RayFileError&) {
  }
  try {
    (void)accelviz::read_occlusion(path);
  } catch (const accelviz::RayFileError&) {
  }
  return 0;
}
