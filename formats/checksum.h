// Content checksums for the container and for provenance input hashes.
//
// FNV-1a 64 (Fowler, Noll, Vo; http://www.isthe.com/chongo/tech/comp/fnv/): a standard,
// dependency-free hash any tool can recompute. Each step $h \leftarrow (h \oplus b) \cdot p$ with
// an odd prime p is a bijection of h, so two inputs of equal length that differ in one byte
// always hash differently: every single corrupted byte is detected. It is not cryptographic;
// it guards against accidents (truncation, bit rot, stale files), not attackers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace rad {

constexpr uint64_t kFnv1a64Offset = 0xcbf29ce484222325ull;
constexpr uint64_t kFnv1a64Prime = 0x100000001b3ull;

// Continues the hash `h` over `size` bytes; pass the previous result to hash in pieces.
inline uint64_t fnv1a64(const void* data, std::size_t size, uint64_t h = kFnv1a64Offset) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) h = (h ^ p[i]) * kFnv1a64Prime;
  return h;
}

// "fnv1a64:" followed by 16 lowercase hex digits: the algorithm is named so it can change
// without ambiguity.
std::string formatFnv1a64(uint64_t h);

}  // namespace rad
