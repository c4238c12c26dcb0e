// Single-part float OpenEXR images (frames of rad-reference and rad-compose, inputs of
// rad-diff). Scanline, ZIP, FLOAT channels; row 0 of the FloatImage is the top of the data
// window (EXR y grows downwards, so no flip).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "libcommon/float_image.h"

namespace rad {

// Reads the named channels of the first part (any pixel type, converted to float). Throws
// rad::inputError(path, ...) if the file is unreadable or lacks a channel (the message lists
// the channels it has).
FloatImage readExrImage(const std::string& path,
                        const std::vector<std::string>& channels = {"R", "G", "B"});

// Writes image atomically (AtomicFile) as FLOAT channels with the given string attributes
// (e.g. "rad.provenance"). Throws rad::outputError(path, ...) on failure.
void writeExrImage(const std::string& path, const FloatImage& image,
                   const std::map<std::string, std::string>& stringAttributes = {});

}  // namespace rad
