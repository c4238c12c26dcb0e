// libFuzzer harness: any bytes as a texture movie (formats/texture_movie.h); what is called is in
// fuzz_readers.h.
#include <cstdint>

#include "tests/fuzz/fuzz_readers.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  rad::fuzz::feedTextureMovie(data, size);
  return 0;
}
