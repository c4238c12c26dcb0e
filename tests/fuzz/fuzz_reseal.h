// Re-seals a mutated rad container so its checksums match again (formats/container.md
// "Checksums"). Without this almost every mutation of a linkhier or intervals file dies at the
// container's checksum test and the kind's own reader is never reached; with it the fuzzer
// explores the reader's validation of metadata and array contents. fuzz_container covers the
// checksum tests themselves on the raw bytes.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "formats/checksum.h"

namespace rad::fuzz {

inline uint64_t readU64(const uint8_t* p) {
  uint64_t v;
  std::memcpy(&v, p, 8);
  return v;
}

// Each array's "hash" string is rewritten in place (same length, so nothing moves), then the
// header checksum. Bytes that do not parse as a container are returned unchanged.
inline std::vector<uint8_t> resealContainer(const uint8_t* data, size_t size) {
  std::vector<uint8_t> bytes(data, data + size);
  constexpr size_t kPreamble = 32;
  if (size < kPreamble) return bytes;
  const uint64_t headerLength = readU64(bytes.data() + 16);
  if (headerLength > size - kPreamble) return bytes;
  std::string header(reinterpret_cast<const char*>(bytes.data() + kPreamble), headerLength);
  const nlohmann::json j = nlohmann::json::parse(header, nullptr, /*allow_exceptions=*/false);
  const uint64_t dataStart = (kPreamble + headerLength + 63) / 64 * 64;
  if (j.is_object() && j.contains("arrays") && j["arrays"].is_array()) {
    for (const nlohmann::json& a : j["arrays"]) {
      if (!a.is_object() || !a.contains("hash") || !a["hash"].is_string()) continue;
      if (!a.contains("offset") || !a["offset"].is_number_unsigned()) continue;
      if (!a.contains("nbytes") || !a["nbytes"].is_number_unsigned()) continue;
      const uint64_t offset = a["offset"], nbytes = a["nbytes"];
      if (offset > size || nbytes > size || dataStart + offset + nbytes > size) continue;
      const std::string old = a["hash"];
      const std::string now = formatFnv1a64(fnv1a64(bytes.data() + dataStart + offset, nbytes));
      const size_t at = header.find("\"" + old + "\"");
      if (old.size() != now.size() || at == std::string::npos) continue;
      header.replace(at + 1, now.size(), now);
    }
    std::memcpy(bytes.data() + kPreamble, header.data(), headerLength);
  }
  const uint64_t checksum = fnv1a64(header.data(), headerLength, fnv1a64(bytes.data(), 24));
  std::memcpy(bytes.data() + 24, &checksum, 8);
  return bytes;
}

}  // namespace rad::fuzz
