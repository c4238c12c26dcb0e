#include "formats/exr_info.h"

#include <OpenEXR/ImfBoxAttribute.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfChannelListAttribute.h>
#include <OpenEXR/ImfCompressionAttribute.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfFloatAttribute.h>
#include <OpenEXR/ImfFloatVectorAttribute.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfStringVectorAttribute.h>
#include <OpenEXR/ImfVecAttribute.h>

#include "formats/exr_header_scan.h"
#include "formats/pixel_checksum.h"
#include "formats/provenance.h"
#include "libcommon/core/error.h"

namespace rad {

namespace {

nlohmann::json attributeValue(const Imf::Attribute& a) {
  using namespace Imf;
  // Attribute strings are bytes; JSON needs UTF-8 (shown with U+FFFD where they are not).
  if (auto* s = dynamic_cast<const StringAttribute*>(&a)) return rad::toValidUtf8(s->value());
  if (auto* i = dynamic_cast<const IntAttribute*>(&a)) return i->value();
  if (auto* f = dynamic_cast<const FloatAttribute*>(&a)) return f->value();
  if (auto* d = dynamic_cast<const DoubleAttribute*>(&a)) return d->value();
  if (auto* v = dynamic_cast<const FloatVectorAttribute*>(&a)) return v->value();
  if (auto* v = dynamic_cast<const StringVectorAttribute*>(&a)) {
    nlohmann::json strings = nlohmann::json::array();
    for (const std::string& s : v->value()) strings.push_back(rad::toValidUtf8(s));
    return strings;
  }
  if (auto* b = dynamic_cast<const Box2iAttribute*>(&a)) {
    const auto& r = b->value();
    return {r.min.x, r.min.y, r.max.x, r.max.y};
  }
  if (auto* v = dynamic_cast<const V2iAttribute*>(&a)) return {v->value().x, v->value().y};
  if (auto* v = dynamic_cast<const V2fAttribute*>(&a)) return {v->value().x, v->value().y};
  if (auto* v = dynamic_cast<const V3fAttribute*>(&a)) {
    return {v->value().x, v->value().y, v->value().z};
  }
  if (auto* c = dynamic_cast<const CompressionAttribute*>(&a)) return int(c->value());
  if (auto* c = dynamic_cast<const ChannelListAttribute*>(&a)) {
    nlohmann::json names = nlohmann::json::array();
    for (auto it = c->value().begin(); it != c->value().end(); ++it)
      names.push_back(rad::toValidUtf8(it.name()));
    return names;
  }
  return std::string("<") + a.typeName() + ">";
}

const char* pixelTypeName(Imf::PixelType t) {
  switch (t) {
    case Imf::UINT:
      return "uint";
    case Imf::HALF:
      return "half";
    case Imf::FLOAT:
      return "float";
    default:
      return "unknown";
  }
}

const char* compressionName(Imf::Compression c) {
  static const char* const kNames[] = {"none",  "rle", "zips", "zip",  "piz",
                                       "pxr24", "b44", "b44a", "dwaa", "dwab"};
  return int(c) >= 0 && int(c) < 10 ? kNames[int(c)] : "unknown";
}

// Any of the attributes every rad EXR writer puts in its parts.
bool hasRadAttributes(const Imf::Header& h) {
  for (const char* name : {"rad.format", kPixelChecksumAttribute, "rad.provenance"})
    if (h.find(name) != h.end()) return true;
  return false;
}

}  // namespace

nlohmann::json readExrInfo(const std::string& path) {
  scanExrFile(path);  // sizes the headers declare, bounded by the file's before OpenEXR reads
  try {
    Imf::MultiPartInputFile file(path.c_str());
    nlohmann::json parts = nlohmann::json::array();
    bool radAttributes = false;
    std::string foreignWriter;
    for (int p = 0; p < file.parts(); ++p) {
      const Imf::Header& h = file.header(p);
      radAttributes = radAttributes || hasRadAttributes(h);
      if (foreignWriter.empty()) foreignWriter = exrForeignWriter(h);
      nlohmann::json part;
      part["name"] = h.hasName() ? rad::toValidUtf8(h.name()) : "";
      part["type"] = h.hasType() ? rad::toValidUtf8(h.type()) : "scanlineimage";
      const auto& dw = h.dataWindow();
      part["width"] = dw.max.x - dw.min.x + 1;
      part["height"] = dw.max.y - dw.min.y + 1;
      nlohmann::json channels = nlohmann::json::array();
      for (auto it = h.channels().begin(); it != h.channels().end(); ++it) {
        channels.push_back(
            {{"name", rad::toValidUtf8(it.name())}, {"type", pixelTypeName(it.channel().type)}});
      }
      part["channels"] = channels;
      part["compression"] = compressionName(h.compression());
      nlohmann::json attrs = nlohmann::json::object();
      for (auto it = h.begin(); it != h.end(); ++it)
        attrs[rad::toValidUtf8(it.name())] = attributeValue(it.attribute());
      // A damaged provenance is an error naming the file, not a JSON exception.
      if (const auto* pv = h.findTypedAttribute<Imf::StringAttribute>("rad.provenance"))
        rad::parseProvenanceJson(pv->value(),
                                 path + ": part " + std::to_string(p) + ": rad.provenance");
      part["attributes"] = attrs;
      parts.push_back(part);
    }
    nlohmann::json info = {{"parts", parts},
                           {"written_by_rad", radAttributes && foreignWriter.empty()}};
    if (!radAttributes) info["foreign_writer"] = "no rad.* attributes";
    if (!foreignWriter.empty()) info["foreign_writer"] = rad::toValidUtf8(foreignWriter);
    return info;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw inputError(path, std::string("not a readable OpenEXR file: ") + e.what());
  }
}

}  // namespace rad
