// libFuzzer harness: any bytes as a frame EXR (formats/frame_image.h, exr_image.h); what is called
// is in fuzz_readers.h.
#include <cstdint>

#include "tests/fuzz/fuzz_readers.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  rad::fuzz::feedFrame(data, size);
  return 0;
}
