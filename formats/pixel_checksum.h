// rad.pixelChecksum: a checksum of the pixels of one OpenEXR part, written by every rad EXR writer
// (texture movies, frames, rad-reference's frames) and verified by every reader, so a flipped
// byte or a truncated chunk is an error rather than a silently wrong pixel (issue 18). Defined in
// formats/texture_movie.md and formats/frame_image.md:
//
//   FNV-1a 64 (formats/checksum.h) over the part's decoded values, scan line by scan line from
//   the data window's first, within a line channel by channel in the part's channel-list order
//   (OpenEXR sorts by name: B, G, R), within a channel left to right; each value as the 4 bytes,
//   little-endian, of its 32-bit float (a HALF value converted to float exactly; a UINT value,
//   item buffers' ids, as its own uint32). The attribute is a string "fnv1a64:<16 hex digits>".
//
// For FLOAT channels that is the byte order of an uncompressed part's chunk data, so a writer
// hashes what it writes and a reader what it decodes, with no second pass over the file.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <OpenEXR/ImfForward.h>
#include <nlohmann/json.hpp>

namespace rad {

constexpr const char* kPixelChecksumAttribute = "rad.pixelChecksum";
// What a writer puts in the attribute until the pixels are written (the same length as a
// checksum, and not one: a reader refuses it as malformed).
constexpr const char* kPixelChecksumPlaceholder = "fnv1a64:????????????????";

// Checksum of `height` rows of `width` interleaved pixels of `channels` floats each.
// listOrder[i] is the index within a pixel of the i-th channel of the part's channel list.
uint64_t pixelChecksum(const float* pixels, int width, int height, int channels,
                       const std::vector<int>& listOrder);
// Interleaved R, G, B pixels (list order B, G, R).
uint64_t rgbPixelChecksum(const float* rgb, int width, int height);

// The value of "fnv1a64:<16 lowercase hex>", or nothing if `text` is not one.
std::optional<uint64_t> parseFnv1a64(const std::string& text);

// A part's stored checksum attribute value (null: the part has none) parsed. Throws
// rad::inputError(path, "<part>: no ...") or "<part>: malformed ..." unless it is one.
uint64_t requiredPixelChecksum(const std::string* stored, const std::string& path,
                               const std::string& part);

// The program that rewrote an OpenEXR part, when a header says it was not rad; empty when
// nothing does. A re-saved rad file (`oiiotool frame.exr -d half --compression dwaa -o x.exr`)
// keeps the rad.* attributes of the file it was made from, rad.pixelChecksum included, but not
// its pixels: such a part is another program's EXR, not a corrupted rad one. The tells, none of
// which a rad writer produces: a "Software" string attribute that does not start with "rad"
// (OpenImageIO, Blender and Nuke write one; the value is returned, cut at 200 bytes), or a
// lossy compression (PXR24, B44, B44A, DWAA, DWAB: "a program writing DWAA compression").
std::string exrForeignWriter(const Imf::Header& header);

// The checksum a part's header stores, parsed. Throws rad::inputError(path, "<part>: ...") if
// the attribute is malformed, or missing where the part's rad.format version requires it
// (frame >= 2, texture-movie >= 2); an older version of those is refused with the stage to
// re-run. Nothing for a part that has none and need not (rad-reference's older frames, EXR
// files from other programs), nor for a part another program rewrote (exrForeignWriter): its
// rad.* attributes describe the file it was made from.
std::optional<uint64_t> storedPixelChecksum(const Imf::Header& header, const std::string& path,
                                            const std::string& part);

// Throws rad::inputError(path, "<part>: pixel checksum mismatch ...") unless equal.
void requirePixelChecksum(uint64_t stored, uint64_t computed, const std::string& path,
                          const std::string& part);

// Reads every pixel of every scan-line part of an OpenEXR file (all channels) and verifies each
// part's checksum (storedPixelChecksum). Throws rad::inputError(path, ...) for an unreadable,
// truncated or corrupted file. Returns {"parts": n, "checksummed_parts": m}.
nlohmann::json verifyExrPixels(const std::string& path);
// The same for parts [firstPart, parts) of a file already open (readExrImage reads part 0 itself
// and verifies the others with this). Returns the number of parts verified against a checksum.
int verifyExrPartPixels(Imf::MultiPartInputFile& file, const std::string& path, int firstPart);

// Offsets of the value of string attribute `name` in each of the first `parts` headers of an
// OpenEXR file whose first bytes are `bytes` (magic, version, headers); a part without it gets
// no entry. Throws rad::Error(kInternal) if the headers are cut short. For writers that fill in
// an attribute after the pixels (TextureMovieWriter's checksums).
std::vector<uint64_t> exrStringAttributeOffsets(const std::vector<char>& bytes, int parts,
                                                const std::string& name);

}  // namespace rad
