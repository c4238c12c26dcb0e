// libFuzzer harness: a mutated key window file (formats/key_window.h) read against the bundled
// scene its seeds were computed for (tests/fuzz/make_seeds.sh); what is called is in
// fuzz_readers.h.
#include <cstdint>

#include "tests/fuzz/fuzz_readers.h"

namespace {
const rad::Scene& scene() {
  static const rad::Scene s =
      rad::readGltfScene(RAD_SOURCE_DIR "/pipelines/scenes/cornell-moving.gltf");
  return s;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  rad::fuzz::feedKeyWindow(data, size, scene());
  return 0;
}
