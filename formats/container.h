// The rad container: one self-describing binary layout shared by every rad-specific file
// (global.rlh, intervals.rti, ...). Byte layout and version history: formats/container.md.
//
// A fixed 32-byte preamble (magic, container version, header length, header checksum), a JSON
// header (kind and its own version, provenance, free metadata, array table), then raw
// little-endian arrays, each 64-byte aligned so the file can be mmap-ed and read as typed
// arrays. Readers validate everything before handing out data: a truncated, corrupted or
// newer file is a one-line rad::inputError naming the file, never a crash.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "formats/provenance.h"
#include "libcommon/core/error.h"

namespace rad {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "the container stores little-endian arrays and copies them verbatim");

constexpr int kContainerMajor = 1;
constexpr int kContainerMinor = 0;
// Every array starts at a multiple of this (from the file start), enough for any SIMD load.
constexpr uint64_t kContainerAlignment = 64;

enum class DType { kU8, kU16, kU32, kU64, kI32, kI64, kF32, kF64 };

const char* dtypeName(DType t);  // "u8", ..., "f64"
std::size_t dtypeSize(DType t);  // bytes per element
bool parseDType(const std::string& name, DType& out);

template <class T>
constexpr DType dtypeOf() {
  if constexpr (std::is_same_v<T, uint8_t>)
    return DType::kU8;
  else if constexpr (std::is_same_v<T, uint16_t>)
    return DType::kU16;
  else if constexpr (std::is_same_v<T, uint32_t>)
    return DType::kU32;
  else if constexpr (std::is_same_v<T, uint64_t>)
    return DType::kU64;
  else if constexpr (std::is_same_v<T, int32_t>)
    return DType::kI32;
  else if constexpr (std::is_same_v<T, int64_t>)
    return DType::kI64;
  else if constexpr (std::is_same_v<T, float>)
    return DType::kF32;
  else if constexpr (std::is_same_v<T, double>)
    return DType::kF64;
  else
    static_assert(!sizeof(T), "no container dtype for this element type");
}

struct ArrayInfo {
  std::string name;
  DType dtype = DType::kU8;
  std::vector<uint64_t> shape;  // row-major (C order); a read shape [] holds 1 element
  uint64_t offset = 0;          // from the start of the data section; multiple of 64
  uint64_t nbytes = 0;          // == dtypeSize(dtype) * product(shape)
  std::string hash;             // "fnv1a64:<16 hex>" of the nbytes bytes

  uint64_t count() const;  // number of elements, product(shape)
};

class ContainerWriter {
 public:
  // `kind` names the file type ("linkhier", "intervals"); its version is independent of the
  // container's: a kind's major changes when its arrays or metadata change incompatibly.
  ContainerWriter(std::string kind, int kindMajor, int kindMinor);

  void setProvenance(const Provenance& provenance) { provenance_ = provenance.toJson(); }
  // Free JSON object whose keys the kind defines; starts as {}.
  nlohmann::json& metadata() { return metadata_; }

  // Copies `values` as array `name`. An empty `shape` means 1-D {values.size()} (scalars belong
  // in metadata); otherwise its product must equal
  // values.size(). A duplicate name or a wrong shape is a programming error
  // (rad::Error kInternal).
  template <class T>
  void addArray(const std::string& name, const std::vector<T>& values,
                std::vector<uint64_t> shape = {}) {
    if (shape.empty()) shape = {static_cast<uint64_t>(values.size())};
    addRaw(name, dtypeOf<T>(), std::move(shape), values.data(), values.size() * sizeof(T));
  }
  // Untyped form of addArray: `nbytes` bytes at `data`, already little-endian.
  void addRaw(const std::string& name, DType dtype, std::vector<uint64_t> shape, const void* data,
              std::size_t nbytes);
  // Like addArray / addRaw but without the copy: the writer keeps `data` and reads it again in
  // write() / serialize(), so it must stay alive and unchanged until then (large outputs are
  // then held once, not twice). The file's bytes are the same as with addArray.
  template <class T>
  void addArrayView(const std::string& name, const std::vector<T>& values,
                    std::vector<uint64_t> shape = {}) {
    if (shape.empty()) shape = {static_cast<uint64_t>(values.size())};
    addRawView(name, dtypeOf<T>(), std::move(shape), values.data(), values.size() * sizeof(T));
  }
  void addRawView(const std::string& name, DType dtype, std::vector<uint64_t> shape,
                  const void* data, std::size_t nbytes);

  // Serialises the whole file to memory (used by write(); handy for tests).
  std::vector<uint8_t> serialize() const;
  // Atomic: writes a hidden temporary beside `path`, fsyncs and renames it (AtomicFile). On
  // failure nothing appears at `path`, no temporary is left, and rad::outputError(path, ...)
  // is thrown. Streams the arrays to the file (the bytes of serialize(), never all in memory).
  void write(const std::string& path) const;

 private:
  struct Pending {
    ArrayInfo info;
    std::vector<uint8_t> bytes;     // addArray / addRaw: the copy
    const uint8_t* view = nullptr;  // addArrayView / addRawView: the caller's bytes
    const uint8_t* data() const { return view ? view : bytes.data(); }
  };
  void addPending(const std::string& name, DType dtype, std::vector<uint64_t> shape,
                  const void* data, std::size_t nbytes, bool copy);
  // Preamble + JSON header + zero padding up to the data section; each array's offset in it.
  std::vector<uint8_t> headerBytes(std::vector<uint64_t>& offsets, uint64_t& dataBytes) const;
  std::string kind_;
  int kindMajor_, kindMinor_;
  nlohmann::json provenance_;  // null until setProvenance
  nlohmann::json metadata_ = nlohmann::json::object();
  std::vector<Pending> arrays_;
};

class ContainerReader {
 public:
  // Reads the whole file and validates it before returning: magic, container version (a newer
  // major is refused), header length and checksum, JSON structure, each array's dtype, shape,
  // alignment, bounds, overlap and checksum, and that all padding is zero. Throws
  // rad::inputError(path, "...") naming the first problem found.
  static ContainerReader open(const std::string& path);
  // Same, on bytes already in memory; `where` is used in error messages.
  static ContainerReader fromBytes(std::vector<uint8_t> bytes, const std::string& where);

  // True when the file starts with the container magic (does not validate further). False if
  // it cannot be read.
  static bool looksLikeContainer(const std::string& path);

  const std::string& path() const { return path_; }
  std::pair<int, int> containerVersion() const { return {major_, minor_}; }
  const std::string& kind() const { return kind_; }
  std::pair<int, int> kindVersion() const { return kindVersion_; }
  // Throws inputError "is an intervals file, expected linkhier" or "linkhier 2.0 is newer
  // than supported 1.x" (or "... older than supported ..."). Minor versions only add, so any
  // minor of the supported major is accepted.
  void requireKind(const std::string& kind, int supportedMajor) const;

  const nlohmann::json& header() const { return header_; }
  const Provenance& provenance() const { return provenance_; }
  const nlohmann::json& metadata() const { return header_.at("metadata"); }
  const std::vector<ArrayInfo>& arrays() const { return arrays_; }
  bool has(const std::string& name) const { return find(name) != nullptr; }
  // Throws inputError "no array 'x'" if absent.
  const ArrayInfo& info(const std::string& name) const;

  // A copy of array `name`; throws inputError if it is missing or its dtype is not T's
  // ("array 'links' is f32, expected u32").
  template <class T>
  std::vector<T> array(const std::string& name) const {
    const ArrayInfo& a = checkedInfo(name, dtypeOf<T>());
    std::vector<T> out(static_cast<std::size_t>(a.count()));
    if (a.nbytes) std::memcpy(out.data(), data(a), a.nbytes);
    return out;
  }
  // Pointer to the array's bytes inside the file buffer (valid while the reader lives).
  const uint8_t* data(const ArrayInfo& a) const { return bytes_.data() + dataStart_ + a.offset; }

  // Content hash of the whole file, same as hashFile(path()).
  std::string fileHash() const;
  // Multi-line summary for rad-inspect: kind, versions, metadata, array table.
  std::string summary() const;

 private:
  ContainerReader() = default;
  // validate() is these steps, in this order (a newer version is reported before "corrupt"):
  void validate();
  uint64_t validatePreamble();                 // magic, version, header length and checksum
  void validateHeader(uint64_t headerLength);  // JSON, kind, kind_version, metadata, provenance
  uint64_t validateArrayTable();               // every entry; returns the data section's end
  ArrayInfo arrayEntry(const nlohmann::json& entry, std::size_t index) const;
  void validateFileSize(uint64_t dataEnd) const;      // truncation, trailing bytes
  void validatePadding(uint64_t headerLength) const;  // overlaps, nonzero padding
  void validateChecksums() const;                     // every array's hash
  const ArrayInfo* find(const std::string& name) const;
  const ArrayInfo& checkedInfo(const std::string& name, DType dtype) const;

  std::string path_;
  std::vector<uint8_t> bytes_;
  int major_ = 0, minor_ = 0;
  uint64_t dataStart_ = 0;
  std::string kind_;
  std::pair<int, int> kindVersion_{0, 0};
  nlohmann::json header_;
  Provenance provenance_;
  std::vector<ArrayInfo> arrays_;
};

// Appends an InputRecord for `path`: its hash, and if it is a rad container its provenance as
// history. A file that starts with the container magic but does not open is an error (the
// caller would fail to read it anyway); any other file gets a null history.
void addInput(Provenance& provenance, const std::string& path);
// Same for a container already open: no second read of the file.
void addInput(Provenance& provenance, const ContainerReader& input);
// The record addInput appends for a container, for a caller that must release the reader
// before the provenance exists (rad-compose drops global.rlh's bytes once read).
InputRecord inputRecordOf(const ContainerReader& input);

}  // namespace rad
