// Message text of the glTF reader (gltf_message_text.h).
#include "formats/gltf_message_text.h"

#include <sstream>

namespace rad {

std::string clipped(const std::string& s, size_t max) {
  if (s.size() <= max) return s;
  size_t end = max;
  while (end > 0 && (static_cast<unsigned char>(s[end]) & 0xC0) == 0x80) --end;
  return s.substr(0, end) + "…";
}
std::string clipInput(const std::string& s) {
  return clipped(s, kMaxQuoted);
}

std::string oneLine(const std::string& text) {
  std::string out, word;
  auto flush = [&] {
    if (word.empty()) return;
    if (!out.empty()) out += ' ';
    out += clipInput(word);
    word.clear();
  };
  for (char c : text) {
    if (c == '\n' || c == '\r' || c == ' ' || c == '\t')
      flush();
    else
      word += c;
  }
  flush();
  return clipped(out, 4 * kMaxQuoted);
}

std::string number(double x) {
  std::ostringstream os;
  os.precision(6);
  os << x;
  return os.str();
}

}  // namespace rad
