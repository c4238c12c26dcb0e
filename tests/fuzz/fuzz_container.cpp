// libFuzzer harness: any bytes as a rad container (formats/container.h); what is called is in
// fuzz_readers.h.
#include <cstdint>

#include "tests/fuzz/fuzz_readers.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  rad::fuzz::feedContainer(data, size);
  return 0;
}
