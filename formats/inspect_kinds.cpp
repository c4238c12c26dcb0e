#include "formats/inspect_kinds.h"

#include <sstream>

namespace rad {

nlohmann::json summarizeContainerContent(const ContainerReader& reader) {
  // Kinds register here as their stages land (linkhier, intervals).
  (void)reader;
  return nullptr;
}

std::string contentSummaryText(const nlohmann::json& content) {
  std::ostringstream os;
  for (const auto& [k, v] : content.items()) os << "  " << k << ": " << v.dump() << "\n";
  return os.str();
}

}  // namespace rad
