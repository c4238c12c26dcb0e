// libFuzzer harness: any bytes as a glTF scene (formats/gltf_scene.h); what is called is in
// fuzz_readers.h.
#include <cstdint>

#include "tests/fuzz/fuzz_readers.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  rad::fuzz::copyGltfSidecars(RAD_SOURCE_DIR);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  rad::fuzz::feedGltf(data, size);
  return 0;
}
