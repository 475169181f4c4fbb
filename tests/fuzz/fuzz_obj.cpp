// libFuzzer target: the Wavefront OBJ loader. SceneError is expected on bad
// input; anything else is a finding (see fuzz_gltf.cpp).
#include "core/scene/load.h"
#include "tests/fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = accelviz_fuzz::write_input(data, size, "obj");
  try {
    accelviz::Scene scene = accelviz::load_obj(path);
    scene.flatten();
    (void)scene.bounds();
  } catch (const accelviz::SceneError&) {
  }
  return 0;
}
