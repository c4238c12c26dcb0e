// libFuzzer harness: a mutated intervals.rti (formats/texture_intervals.h); what is called is in
// fuzz_readers.h.
#include <cstdint>

#include "tests/fuzz/fuzz_readers.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  rad::fuzz::feedIntervals(data, size);
  return 0;
}
