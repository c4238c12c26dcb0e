// Content summaries of each container kind, for rad-inspect: the stage that defines a kind
// knows what its arrays mean (movies and their close reasons, links and their labels, ...).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "formats/container.h"

namespace rad {

// null for a kind without a content summary.
nlohmann::json summarizeContainerContent(const ContainerReader& reader);
std::string contentSummaryText(const nlohmann::json& content);

}  // namespace rad
