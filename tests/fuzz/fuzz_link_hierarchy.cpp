// libFuzzer harness: a mutated global.rlh (formats/link_hierarchy.h) read against the bundled
// scene its seeds were computed for (tests/fuzz/make_seeds.sh); what is called is in
// fuzz_readers.h.
#include <cstdint>

#include "tests/fuzz/fuzz_readers.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  rad::fuzz::feedLinkHierarchy(data, size, rad::fuzz::bundledScene());
  return 0;
}
