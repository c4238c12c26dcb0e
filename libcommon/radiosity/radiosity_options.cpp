// The refinement oracle's names; see radiosity_options.h.
#include "libcommon/radiosity/radiosity_options.h"

#include "libcommon/core/error.h"

namespace rad {

RefinementOracle parseRefinementOracle(const std::string& name) {
  if (name == "power") return RefinementOracle::kPower;
  if (name == "error") return RefinementOracle::kError;
  if (name == "both") return RefinementOracle::kBoth;
  throw Error(ExitCode::kUsage, "",
              "refinement oracle '" + name + "'; expected power, error or both");
}

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
