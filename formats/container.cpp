#include "formats/container.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <limits>
#include <sstream>

#include "formats/atomic_file.h"
#include "formats/checksum.h"

namespace rad {

namespace {

// PNG-style magic: a non-ASCII first byte (not a text file), "RAD", then CR LF, ^Z, LF, which
// any newline translation or 7-bit transfer visibly damages.
constexpr unsigned char kMagic[8] = {0x89, 'R', 'A', 'D', '\r', '\n', 0x1a, '\n'};
constexpr uint64_t kPreambleSize = 32;
// Bytes of the preamble covered by the header checksum (everything before the checksum).
constexpr uint64_t kChecksummedPreamble = 24;
// More dimensions than this is certainly corruption; keeps shape products cheap to check.
constexpr std::size_t kMaxDims = 16;
// Provenance histories nest about 3 levels per tool in the chain; 200 leaves room for long
// pipelines while bounding recursion in nlohmann::json.
constexpr int kMaxJsonDepth = 200;

uint64_t alignUp(uint64_t x) {
  return (x + kContainerAlignment - 1) / kContainerAlignment * kContainerAlignment;
}

template <class T>
T loadLE(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

template <class T>
void storeLE(std::vector<uint8_t>& out, T v) {
  const auto* p = reinterpret_cast<const uint8_t*>(&v);
  out.insert(out.end(), p, p + sizeof v);
}

std::string versionText(uint64_t major, uint64_t minor) {
  return std::to_string(major) + "." + std::to_string(minor);
}

std::string withArticle(const std::string& word) {
  const bool vowel = !word.empty() && std::strchr("aeiouAEIOU", word[0]) != nullptr;
  return (vowel ? "an " : "a ") + word;
}

// Reads the whole of a regular file; inputError on anything else.
std::vector<uint8_t> readWholeFile(const std::string& path) {
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw inputError(path, std::string("cannot open: ") + std::strerror(errno));
  struct stat st;
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    throw inputError(path, "not a regular file");
  }
  std::vector<uint8_t> bytes(static_cast<std::size_t>(st.st_size));
  std::size_t got = 0;
  while (got < bytes.size()) {
    const ssize_t n = ::read(fd, bytes.data() + got, bytes.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int err = errno;
      ::close(fd);
      throw inputError(path, std::string("cannot read: ") + std::strerror(err));
    }
    if (n == 0) break;  // shrank while reading
    got += static_cast<std::size_t>(n);
  }
  ::close(fd);
  bytes.resize(got);
  return bytes;
}

// Deepest bracket nesting in JSON text. nlohmann::json parses iteratively but copies, compares,
// dumps and (before 3.11) destroys recursively, so a hostile header of a million '[' would
// overflow the stack; the header is refused before parsing instead. Exact for valid JSON, which
// is all that matters since invalid JSON fails to parse anyway.
int jsonDepth(const uint8_t* text, uint64_t size) {
  int depth = 0, maxDepth = 0;
  bool inString = false, escaped = false;
  for (uint64_t i = 0; i < size; ++i) {
    const uint8_t c = text[i];
    if (inString) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        inString = false;
    } else if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      maxDepth = std::max(maxDepth, ++depth);
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return maxDepth;
}

// Names go into one-line error messages and rad-inspect tables.
bool hasControlCharacter(const std::string& s) {
  for (unsigned char c : s) {
    if (c < 0x20 || c == 0x7f) return true;
  }
  return false;
}

bool isUnsigned(const nlohmann::json& j) {
  return j.is_number_unsigned();
}

// Member `key` of `obj`, or null when absent: const operator[] on a missing key is undefined
// behaviour in nlohmann::json, and the non-const one would insert it.
const nlohmann::json& field(const nlohmann::json& obj, const char* key) {
  static const nlohmann::json kNull;
  if (!obj.is_object()) return kNull;
  const auto it = obj.find(key);
  return it == obj.end() ? kNull : *it;
}

}  // namespace

const char* dtypeName(DType t) {
  switch (t) {
    case DType::kU8:
      return "u8";
    case DType::kU16:
      return "u16";
    case DType::kU32:
      return "u32";
    case DType::kU64:
      return "u64";
    case DType::kI32:
      return "i32";
    case DType::kI64:
      return "i64";
    case DType::kF32:
      return "f32";
    case DType::kF64:
      return "f64";
  }
  return "?";
}

std::size_t dtypeSize(DType t) {
  switch (t) {
    case DType::kU8:
      return 1;
    case DType::kU16:
      return 2;
    case DType::kU32:
    case DType::kI32:
    case DType::kF32:
      return 4;
    case DType::kU64:
    case DType::kI64:
    case DType::kF64:
      return 8;
  }
  return 1;
}

bool parseDType(const std::string& name, DType& out) {
  for (DType t : {DType::kU8, DType::kU16, DType::kU32, DType::kU64, DType::kI32, DType::kI64,
                  DType::kF32, DType::kF64}) {
    if (name == dtypeName(t)) {
      out = t;
      return true;
    }
  }
  return false;
}

uint64_t ArrayInfo::count() const {
  uint64_t n = 1;
  for (uint64_t d : shape) n *= d;  // validated against overflow when read
  return n;
}

// ---------------------------------------------------------------------------------- writer

ContainerWriter::ContainerWriter(std::string kind, int kindMajor, int kindMinor)
    : kind_(std::move(kind)), kindMajor_(kindMajor), kindMinor_(kindMinor) {
  if (kind_.empty() || kindMajor_ < 0 || kindMinor_ < 0) {
    throw Error(ExitCode::kInternal, "container", "empty kind or negative kind version");
  }
}

void ContainerWriter::addRaw(const std::string& name, DType dtype, std::vector<uint64_t> shape,
                             const void* data, std::size_t nbytes) {
  addPending(name, dtype, std::move(shape), data, nbytes, true);
}

void ContainerWriter::addRawView(const std::string& name, DType dtype, std::vector<uint64_t> shape,
                                 const void* data, std::size_t nbytes) {
  addPending(name, dtype, std::move(shape), data, nbytes, false);
}

void ContainerWriter::addPending(const std::string& name, DType dtype, std::vector<uint64_t> shape,
                                 const void* data, std::size_t nbytes, bool copy) {
  if (name.empty()) throw Error(ExitCode::kInternal, kind_, "array with an empty name");
  for (const auto& p : arrays_) {
    if (p.info.name == name)
      throw Error(ExitCode::kInternal, kind_, "duplicate array '" + name + "'");
  }
  uint64_t count = 1;
  for (uint64_t d : shape) count *= d;
  if (shape.size() > kMaxDims || count * dtypeSize(dtype) != nbytes) {
    throw Error(
        ExitCode::kInternal, kind_,
        "array '" + name + "': shape does not match its " + std::to_string(nbytes) + " bytes");
  }
  Pending p;
  p.info.name = name;
  p.info.dtype = dtype;
  p.info.shape = std::move(shape);
  p.info.nbytes = nbytes;
  if (copy)
    p.bytes.assign(static_cast<const uint8_t*>(data), static_cast<const uint8_t*>(data) + nbytes);
  else
    p.view = nbytes ? static_cast<const uint8_t*>(data) : p.bytes.data();
  p.info.hash = formatFnv1a64(fnv1a64(p.data(), nbytes));
  arrays_.push_back(std::move(p));
}

std::vector<uint8_t> ContainerWriter::headerBytes(std::vector<uint64_t>& offsets,
                                                  uint64_t& dataBytes) const {
  nlohmann::json header;
  header["kind"] = kind_;
  header["kind_version"] = {kindMajor_, kindMinor_};
  header["provenance"] = provenance_;
  header["metadata"] = metadata_;
  nlohmann::json table = nlohmann::json::array();
  uint64_t offset = 0;
  offsets.clear();
  for (const auto& p : arrays_) {
    offsets.push_back(offset);
    table.push_back({{"name", p.info.name},
                     {"dtype", dtypeName(p.info.dtype)},
                     {"shape", p.info.shape},
                     {"offset", offset},
                     {"nbytes", p.info.nbytes},
                     {"hash", p.info.hash}});
    offset = alignUp(offset + p.info.nbytes);
  }
  header["arrays"] = table;
  dataBytes = offset;
  // Indented so `head -c 4000 file` is readable; the cost is a few hundred bytes.
  const std::string text = header.dump(1);

  std::vector<uint8_t> out;
  const uint64_t dataStart = alignUp(kPreambleSize + text.size());
  out.reserve(static_cast<std::size_t>(dataStart));
  out.insert(out.end(), kMagic, kMagic + sizeof kMagic);
  storeLE<uint32_t>(out, kContainerMajor);
  storeLE<uint32_t>(out, kContainerMinor);
  storeLE<uint64_t>(out, text.size());
  const uint64_t sum = fnv1a64(text.data(), text.size(), fnv1a64(out.data(), kChecksummedPreamble));
  storeLE<uint64_t>(out, sum);
  out.insert(out.end(), text.begin(), text.end());
  out.resize(static_cast<std::size_t>(dataStart), 0);
  return out;
}

std::vector<uint8_t> ContainerWriter::serialize() const {
  std::vector<uint64_t> offsets;
  uint64_t dataBytes = 0;
  std::vector<uint8_t> out = headerBytes(offsets, dataBytes);
  const uint64_t dataStart = out.size();
  out.reserve(static_cast<std::size_t>(dataStart + dataBytes));
  for (std::size_t i = 0; i < arrays_.size(); ++i) {
    out.resize(static_cast<std::size_t>(dataStart + offsets[i]), 0);
    out.insert(out.end(), arrays_[i].data(), arrays_[i].data() + arrays_[i].info.nbytes);
  }
  out.resize(static_cast<std::size_t>(dataStart + dataBytes), 0);
  return out;
}

void ContainerWriter::write(const std::string& path) const {
  std::vector<uint64_t> offsets;
  uint64_t dataBytes = 0;
  const std::vector<uint8_t> header = headerBytes(offsets, dataBytes);
  AtomicFile file(path);
  int fd = ::open(file.tempPath().c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) {
    throw outputError(
        path, "cannot create temporary file " + file.tempPath() + ": " + std::strerror(errno));
  }
  // The same bytes as serialize(), array by array with the zero padding between them.
  const uint8_t zeros[kContainerAlignment] = {};
  bool ok = writeAll(fd, header.data(), header.size());
  uint64_t written = 0;  // of the data section
  for (std::size_t i = 0; ok && i <= arrays_.size(); ++i) {
    const uint64_t start = i < arrays_.size() ? offsets[i] : dataBytes;
    ok = writeAll(fd, zeros, static_cast<std::size_t>(start - written));
    written = start;
    if (ok && i < arrays_.size()) {
      ok = writeAll(fd, arrays_[i].data(), static_cast<std::size_t>(arrays_[i].info.nbytes));
      written += arrays_[i].info.nbytes;
    }
  }
  const int err = errno;
  if (::close(fd) != 0 || !ok) {
    throw outputError(path, std::string("cannot write: ") + std::strerror(ok ? errno : err));
  }
  file.commit();
}

// ---------------------------------------------------------------------------------- reader

ContainerReader ContainerReader::open(const std::string& path) {
  return fromBytes(readWholeFile(path), path);
}

ContainerReader ContainerReader::fromBytes(std::vector<uint8_t> bytes, const std::string& where) {
  ContainerReader r;
  r.path_ = where;
  r.bytes_ = std::move(bytes);
  try {
    r.validate();
  } catch (const nlohmann::json::exception& e) {
    // validate() checks types before use; this is a safety net for anything it missed.
    throw inputError(where, std::string("malformed header: ") + e.what());
  }
  return r;
}

bool ContainerReader::looksLikeContainer(const std::string& path) {
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  unsigned char head[sizeof kMagic];
  const ssize_t n = ::read(fd, head, sizeof head);
  ::close(fd);
  return n == static_cast<ssize_t>(sizeof head) && std::memcmp(head, kMagic, sizeof head) == 0;
}

void ContainerReader::validate() {
  const uint64_t headerLength = validatePreamble();
  validateHeader(headerLength);
  const uint64_t dataEnd = validateArrayTable();
  validateFileSize(dataEnd);
  validatePadding(headerLength);
  validateChecksums();
}

uint64_t ContainerReader::validatePreamble() {
  const std::string& p = path_;
  const uint64_t size = bytes_.size();
  const uint8_t* b = bytes_.data();

  // Preamble. Magic and version come first: they are the part of the layout that never changes,
  // so a newer file is reported as newer rather than as corrupt.
  const std::size_t magicLen = static_cast<std::size_t>(std::min<uint64_t>(size, sizeof kMagic));
  if (magicLen > 0 && std::memcmp(b, kMagic, magicLen) != 0)
    throw inputError(p, "bad magic: not a rad container");
  if (size < kPreambleSize) {
    throw inputError(p, "truncated: " + std::to_string(size) + " bytes, shorter than the " +
                            std::to_string(kPreambleSize) + "-byte preamble");
  }
  const uint32_t major = loadLE<uint32_t>(b + 8);
  const uint32_t minor = loadLE<uint32_t>(b + 12);
  if (major > static_cast<uint32_t>(kContainerMajor)) {
    throw inputError(p, "container " + versionText(major, minor) + " is newer than supported " +
                            std::to_string(kContainerMajor) + ".x");
  }
  if (major < static_cast<uint32_t>(kContainerMajor)) {
    throw inputError(p, "container " + versionText(major, minor) + " is older than supported " +
                            std::to_string(kContainerMajor) + ".x");
  }
  major_ = static_cast<int>(major);
  minor_ = static_cast<int>(std::min<uint32_t>(minor, std::numeric_limits<int>::max()));

  const uint64_t headerLength = loadLE<uint64_t>(b + 16);
  if (headerLength > size - kPreambleSize) {
    throw inputError(p, "truncated: preamble says the header ends at byte " +
                            (headerLength > size ? std::string("> ") + std::to_string(size)
                                                 : std::to_string(kPreambleSize + headerLength)) +
                            ", file has " + std::to_string(size) + " bytes");
  }
  const uint64_t storedSum = loadLE<uint64_t>(b + 24);
  const uint64_t sum = fnv1a64(b + kPreambleSize, headerLength, fnv1a64(b, kChecksummedPreamble));
  if (sum != storedSum)
    throw inputError(p, "header checksum mismatch: preamble or header corrupted");
  dataStart_ = alignUp(kPreambleSize + headerLength);
  return headerLength;
}

void ContainerReader::validateHeader(uint64_t headerLength) {
  const std::string& p = path_;
  const uint8_t* b = bytes_.data();
  // JSON header.
  if (jsonDepth(b + kPreambleSize, headerLength) > kMaxJsonDepth) {
    throw inputError(p, "header nests deeper than " + std::to_string(kMaxJsonDepth) + " levels");
  }
  header_ = nlohmann::json::parse(b + kPreambleSize, b + kPreambleSize + headerLength, nullptr,
                                  /*allow_exceptions=*/false);
  if (header_.is_discarded()) throw inputError(p, "header is not valid JSON");
  if (!header_.is_object()) throw inputError(p, "header is not a JSON object");

  const auto& kind = field(header_, "kind");
  if (!kind.is_string() || kind.get_ref<const std::string&>().empty() ||
      hasControlCharacter(kind.get_ref<const std::string&>())) {
    throw inputError(p, "header: missing, empty or unprintable \"kind\"");
  }
  kind_ = kind.get<std::string>();
  const auto& kv = field(header_, "kind_version");
  if (!kv.is_array() || kv.size() != 2 || !isUnsigned(kv[0]) || !isUnsigned(kv[1]) ||
      kv[0].get<uint64_t>() > std::numeric_limits<int>::max() ||
      kv[1].get<uint64_t>() > std::numeric_limits<int>::max()) {
    throw inputError(p, "header: \"kind_version\" is not [major, minor]");
  }
  kindVersion_ = {kv[0].get<int>(), kv[1].get<int>()};
  if (!field(header_, "metadata").is_object())
    throw inputError(p, "header: \"metadata\" is not an object");
  const auto& prov = field(header_, "provenance");
  if (!prov.is_null()) provenance_ = Provenance::fromJson(prov, p + ": provenance");
}

uint64_t ContainerReader::validateArrayTable() {
  const auto& table = field(header_, "arrays");
  if (!table.is_array()) throw inputError(path_, "header: \"arrays\" is not a list");
  uint64_t dataEnd = 0;
  for (std::size_t i = 0; i < table.size(); ++i) {
    ArrayInfo a = arrayEntry(table[i], i);
    dataEnd = std::max(dataEnd, a.offset + a.nbytes);
    arrays_.push_back(std::move(a));
  }
  return dataEnd;
}

ArrayInfo ContainerReader::arrayEntry(const nlohmann::json& e, std::size_t i) const {
  const std::string& p = path_;
  const std::string at = "array #" + std::to_string(i);
  if (!e.is_object()) throw inputError(p, at + " is not an object");
  ArrayInfo a;
  const auto& name = field(e, "name");
  if (!name.is_string() || name.get_ref<const std::string&>().empty() ||
      hasControlCharacter(name.get_ref<const std::string&>())) {
    throw inputError(p, at + ": missing, empty or unprintable name");
  }
  a.name = name.get<std::string>();
  const std::string an = "array '" + a.name + "'";
  if (find(a.name)) throw inputError(p, "duplicate " + an);
  const auto& dt = field(e, "dtype");
  if (!dt.is_string() || !parseDType(dt.get<std::string>(), a.dtype)) {
    throw inputError(p, an + ": unknown dtype " + dt.dump());
  }
  const auto& shape = field(e, "shape");
  if (!shape.is_array() || shape.size() > kMaxDims) throw inputError(p, an + ": bad shape");
  uint64_t n = dtypeSize(a.dtype);
  bool overflow = false;
  for (const auto& d : shape) {
    if (!isUnsigned(d)) throw inputError(p, an + ": bad shape " + shape.dump());
    const uint64_t dim = d.get<uint64_t>();
    a.shape.push_back(dim);
    if (dim != 0 && n > std::numeric_limits<uint64_t>::max() / dim) overflow = true;
    n *= dim;
  }
  if (!isUnsigned(field(e, "offset")) || !isUnsigned(field(e, "nbytes"))) {
    throw inputError(p, an + ": missing offset or nbytes");
  }
  a.offset = field(e, "offset").get<uint64_t>();
  a.nbytes = field(e, "nbytes").get<uint64_t>();
  if (overflow || n != a.nbytes) {
    throw inputError(p, an + ": " + std::to_string(a.nbytes) + " bytes do not match " +
                            dtypeName(a.dtype) + " shape " + shape.dump());
  }
  if (a.offset % kContainerAlignment != 0) {
    throw inputError(p, an + ": offset " + std::to_string(a.offset) + " is not " +
                            std::to_string(kContainerAlignment) + "-byte aligned");
  }
  if (a.offset > std::numeric_limits<uint64_t>::max() - a.nbytes - kContainerAlignment ||
      dataStart_ + a.offset + a.nbytes < dataStart_) {
    throw inputError(p, an + ": extends past end of file");
  }
  const auto& hash = field(e, "hash");
  if (!hash.is_string()) throw inputError(p, an + ": missing hash");
  a.hash = hash.get<std::string>();
  return a;
}

void ContainerReader::validateFileSize(uint64_t dataEnd) const {
  const std::string& p = path_;
  const uint64_t size = bytes_.size();
  // Total size: the header determines it exactly, which catches truncation and appended bytes.
  const uint64_t dataLength = alignUp(dataEnd);
  if (dataLength > std::numeric_limits<uint64_t>::max() - dataStart_) {
    throw inputError(p, "header: arrays extend past end of file");
  }
  const uint64_t expected = dataStart_ + dataLength;
  if (expected > size) {
    throw inputError(p, "truncated: header says " + std::to_string(expected) + " bytes, file has " +
                            std::to_string(size));
  }
  if (expected < size) {
    throw inputError(p, "trailing data: header says " + std::to_string(expected) +
                            " bytes, file has " + std::to_string(size));
  }
}

void ContainerReader::validatePadding(uint64_t headerLength) const {
  const std::string& p = path_;
  const uint64_t size = bytes_.size();
  const uint8_t* b = bytes_.data();
  // Overlaps and padding: every byte not in an array must be zero, so a flipped padding byte is
  // noticed too (the checksums cover everything else).
  std::vector<const ArrayInfo*> order;
  for (const auto& a : arrays_) order.push_back(&a);
  std::sort(order.begin(), order.end(),
            [](const ArrayInfo* x, const ArrayInfo* y) { return x->offset < y->offset; });
  uint64_t cursor = kPreambleSize + headerLength;  // absolute
  auto checkZero = [&](uint64_t from, uint64_t to) {
    for (uint64_t i = from; i < to; ++i) {
      if (b[i] != 0) throw inputError(p, "nonzero padding byte at offset " + std::to_string(i));
    }
  };
  for (const ArrayInfo* a : order) {
    const uint64_t begin = dataStart_ + a->offset;
    if (begin < cursor) {
      throw inputError(p, "array '" + a->name + "' overlaps the previous array");
    }
    checkZero(cursor, begin);
    cursor = begin + a->nbytes;
  }
  checkZero(cursor, size);
}

void ContainerReader::validateChecksums() const {
  const std::string& p = path_;
  const uint8_t* b = bytes_.data();
  for (const auto& a : arrays_) {
    const std::string actual = formatFnv1a64(fnv1a64(b + dataStart_ + a.offset, a.nbytes));
    if (actual != a.hash) {
      throw inputError(p, "array '" + a.name + "': checksum mismatch (data corrupted)");
    }
  }
}

void ContainerReader::requireKind(const std::string& kind, int supportedMajor) const {
  if (kind_ != kind)
    throw inputError(path_, "is " + withArticle(kind_) + " file, expected " + kind);
  const std::string v = versionText(kindVersion_.first, kindVersion_.second);
  if (kindVersion_.first > supportedMajor) {
    throw inputError(path_, kind + " " + v + " is newer than supported " +
                                std::to_string(supportedMajor) + ".x");
  }
  if (kindVersion_.first < supportedMajor) {
    throw inputError(path_, kind + " " + v + " is older than supported " +
                                std::to_string(supportedMajor) + ".x; rebuild it");
  }
}

const ArrayInfo* ContainerReader::find(const std::string& name) const {
  for (const auto& a : arrays_) {
    if (a.name == name) return &a;
  }
  return nullptr;
}

const ArrayInfo& ContainerReader::info(const std::string& name) const {
  const ArrayInfo* a = find(name);
  if (!a) throw inputError(path_, "no array '" + name + "'");
  return *a;
}

const ArrayInfo& ContainerReader::checkedInfo(const std::string& name, DType dtype) const {
  const ArrayInfo& a = info(name);
  if (a.dtype != dtype) {
    throw inputError(
        path_, "array '" + name + "' is " + dtypeName(a.dtype) + ", expected " + dtypeName(dtype));
  }
  return a;
}

std::string ContainerReader::fileHash() const {
  return formatFnv1a64(fnv1a64(bytes_.data(), bytes_.size()));
}

std::string ContainerReader::summary() const {
  std::ostringstream s;
  s << "kind " << kind_ << " " << versionText(kindVersion_.first, kindVersion_.second)
    << " (container " << versionText(major_, minor_) << ", " << bytes_.size() << " bytes)\n";
  s << "metadata " << metadata().dump() << "\n";
  s << "arrays:\n";
  for (const auto& a : arrays_) {
    s << "  " << a.name << " " << dtypeName(a.dtype) << " [";
    for (std::size_t i = 0; i < a.shape.size(); ++i) s << (i ? ", " : "") << a.shape[i];
    s << "] " << a.nbytes << " bytes " << a.hash << "\n";
  }
  return s.str();
}

void addInput(Provenance& provenance, const std::string& path) {
  if (ContainerReader::looksLikeContainer(path)) {
    addInput(provenance, ContainerReader::open(path));
    return;
  }
  provenance.inputs.push_back({path, hashFile(path), nullptr});
}

InputRecord inputRecordOf(const ContainerReader& input) {
  InputRecord r{input.path(), input.fileHash(), nullptr};
  const auto& prov = input.header().find("provenance");
  if (prov != input.header().end() && prov->is_object()) r.history = *prov;
  return r;
}

void addInput(Provenance& provenance, const ContainerReader& input) {
  provenance.inputs.push_back(inputRecordOf(input));
}

}  // namespace rad
