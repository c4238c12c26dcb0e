// The refinement oracle's names; see radiosity_options.h.
#include "libcommon/radiosity/radiosity_options.h"

#include "libcommon/core/error.h"

namespace rad {

const char* refinementOracleName(RefinementOracle oracle) {
  switch (oracle) {
    case RefinementOracle::kPower:
      return "power";
    case RefinementOracle::kError:
      return "error";
    case RefinementOracle::kBoth:
      return "both";
  }
  return "?";
}

}  // namespace rad
