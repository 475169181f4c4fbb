// libFuzzer target: the glTF 2.0 loader (.glb when the input starts with the
// GLB magic "glTF", else .gltf JSON). A SceneError is the loader's answer to
// bad input and is expected; any other exception, a crash, a sanitizer
// report, a hang (-timeout) or unbounded memory (-rss_limit_mb) is a finding.
#include <cstring>

#include "core/scene/load.h"
#include "tests/fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const bool glb = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  const std::string path = accelviz_fuzz::write_input(data, size, glb ? "glb" : "gltf");
  try {
    accelviz::Scene scene = accelviz::load_gltf(path);
    scene.flatten();
    (void)scene.bounds();
  } catch (const accelviz::SceneError&) {
  }
  return 0;
}
