// How the glTF reader quotes input and numbers in its messages (formats/gltf_scene.md "Errors"):
// one line, every quoted word cut, numbers in their shortest form.
#pragma once

#include <cstddef>
#include <string>

namespace rad {

// Quoted input (names, URIs, tinygltf's messages that echo them) is cut at this many bytes:
// a failed data URI used to be echoed whole, a 12 KB error line.
constexpr size_t kMaxQuoted = 120;

// `s` cut to `max` bytes (at a UTF-8 character boundary) with "…" appended when cut.
std::string clipped(const std::string& s, size_t max);
// clipped(s, kMaxQuoted).
std::string clipInput(const std::string& s);
// A library message on one line, every word longer than kMaxQuoted cut (clipInput()), at most
// 4 x kMaxQuoted bytes in all.
std::string oneLine(const std::string& text);
// A value in a message: shortest round-trip form ("1e+38", "0.5").
std::string number(double x);

}  // namespace rad
