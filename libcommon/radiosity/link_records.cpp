// The seeds of a link's shadow rays; see link_records.h.
#include "libcommon/radiosity/link_records.h"

#include "libcommon/radiosity/visibility.h"

namespace rad {

uint64_t linkSeed(PatchId receiver, PatchId shooter) {
  return splitMix64(splitMix64(splitMix64(receiver.packed()) ^ shooter.packed()) +
                    0x9E3779B97F4A7C15ull);
}

uint64_t receiverSeed(PatchId receiver) {
  return splitMix64(splitMix64(receiver.packed()) ^ 0xA0761D6478BD642Full);
}

}  // namespace rad
