#include "formats/inspect_kinds.h"

#include <sstream>

#include "formats/key_window.h"
#include "formats/link_hierarchy.h"
#include "formats/texture_intervals.h"

namespace rad {

nlohmann::json summarizeContainerContent(const ContainerReader& reader) {
  // Each kind's summary lives with its format.
  if (reader.kind() == kLinkHierarchyKind) return summarizeLinkHierarchy(reader);
  if (reader.kind() == kTextureIntervalsKind) return summarizeTextureIntervals(reader);
  if (reader.kind() == kKeyWindowKind) return summarizeKeyWindow(reader);
  return nullptr;
}

std::string contentSummaryText(const nlohmann::json& content) {
  std::ostringstream os;
  for (const auto& [k, v] : content.items()) os << "  " << k << ": " << v.dump() << "\n";
  return os.str();
}

}  // namespace rad
