// What is inside an OpenEXR file: its parts and every header attribute, for rad-inspect.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace rad {

// {"parts": [{"name", "type", "width", "height", "channels": [{"name", "type"}...],
//             "compression", "attributes": {name: value}}],
//  "written_by_rad": bool, "foreign_writer": "..."}
// written_by_rad: a part carries rad's attributes (rad.format, rad.pixelChecksum,
// rad.provenance) and no part was rewritten by another program (exrForeignWriter,
// formats/pixel_checksum.h). Otherwise foreign_writer says why: that program, or
// "no rad.* attributes".
// Strings that are not UTF-8 are shown with U+FFFD. Throws rad::inputError(path, ...) if the
// file is not a readable OpenEXR file or a part's rad.provenance is not a provenance JSON
// (parseProvenanceJson). Headers only: verifyExrPixels (formats/pixel_checksum.h) reads pixels.
nlohmann::json readExrInfo(const std::string& path);

}  // namespace rad
