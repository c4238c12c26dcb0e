#include "libcommon/compose/compose_options.h"

namespace rad {

nlohmann::json ComposeOptions::toJson() const {
  return {{"output", output},
          {"frames", frames},
          {"fps", fps ? nlohmann::json(*fps) : nlohmann::json()},
          {"size", size},
          {"camera", camera},
          {"exposure", exposure.value_or(0.0)},
          {"auto-exposure", autoExposure},
          {"half", half},
          {"compression", compression},
          {"no-png", noPng}};
}

}  // namespace rad
