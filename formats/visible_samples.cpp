#include "formats/visible_samples.h"

namespace rad {

void writeVisibleSamples(const std::string& path, const VisibleSamples& samples,
                         const Provenance& provenance) {
  ContainerWriter w(kVisibleSamplesKind, kVisibleSamplesMajor, kVisibleSamplesMinor);
  w.setProvenance(provenance);
  w.metadata()["parameters"] = samples.parameters;
  const size_t n = samples.frames.size();
  std::vector<int32_t> frame(n);
  std::vector<uint8_t> empty(n);
  std::vector<double> seconds(n);
  std::vector<uint64_t> start(n + 1, 0);
  std::vector<uint32_t> leaf, count;
  for (size_t i = 0; i < n; ++i) {
    const VisibleSamplesFrame& f = samples.frames[i];
    if (f.leaf.size() != f.count.size())
      throw Error(ExitCode::kInternal, path, "leaves and counts differ in number");
    frame[i] = f.frame;
    empty[i] = f.empty ? 1 : 0;
    seconds[i] = f.itemBufferSeconds;
    leaf.insert(leaf.end(), f.leaf.begin(), f.leaf.end());
    count.insert(count.end(), f.count.begin(), f.count.end());
    start[i + 1] = leaf.size();
  }
  w.addArray("frame", frame);
  w.addArray("frame_empty", empty);
  w.addArray("frame_item_buffer_seconds", seconds);
  w.addArray("frame_start", start);
  w.addArray("leaf", leaf);
  w.addArray("count", count);
  w.write(path);
}

VisibleSamples readVisibleSamples(const std::string& path) {
  const ContainerReader r = ContainerReader::open(path);
  r.requireKind(kVisibleSamplesKind, kVisibleSamplesMajor);
  VisibleSamples out;
  if (!r.metadata().contains("parameters") || !r.metadata().at("parameters").is_object())
    throw inputError(path, "metadata: no parameters object");
  out.parameters = r.metadata().at("parameters");
  const std::vector<int32_t> frame = r.array<int32_t>("frame");
  const std::vector<uint8_t> empty = r.array<uint8_t>("frame_empty");
  const std::vector<double> seconds = r.array<double>("frame_item_buffer_seconds");
  const std::vector<uint64_t> start = r.array<uint64_t>("frame_start");
  const std::vector<uint32_t> leaf = r.array<uint32_t>("leaf");
  const std::vector<uint32_t> count = r.array<uint32_t>("count");
  const size_t n = frame.size();
  if (empty.size() != n || seconds.size() != n || start.size() != n + 1 || start[0] != 0 ||
      start[n] != leaf.size() || count.size() != leaf.size())
    throw inputError(path,
                     "arrays: frame, frame_empty, frame_item_buffer_seconds, frame_start, "
                     "leaf and count do not agree in size");
  out.frames.resize(n);
  for (size_t i = 0; i < n; ++i) {
    if (i > 0 && frame[i] <= frame[i - 1]) throw inputError(path, "frames do not increase");
    if (start[i + 1] < start[i]) throw inputError(path, "frame_start decreases");
    VisibleSamplesFrame& f = out.frames[i];
    f.frame = frame[i];
    f.empty = empty[i] != 0;
    f.itemBufferSeconds = seconds[i];
    f.leaf.assign(leaf.begin() + long(start[i]), leaf.begin() + long(start[i + 1]));
    f.count.assign(count.begin() + long(start[i]), count.begin() + long(start[i + 1]));
    for (size_t k = 1; k < f.leaf.size(); ++k)
      if (f.leaf[k] <= f.leaf[k - 1])
        throw inputError(path, "frame " + std::to_string(f.frame) + ": leaves do not increase");
  }
  return out;
}

}  // namespace rad
