// What is inside an OpenEXR file: its parts and every header attribute, for rad-inspect.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace rad {

// {"parts": [{"name", "type", "dataWindow", "channels": [...], "attributes": {name: value}}]}
// Throws rad::inputError(path, ...) if the file is not a readable OpenEXR file.
nlohmann::json readExrInfo(const std::string& path);

}  // namespace rad
