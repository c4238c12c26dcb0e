#include "formats/texture_intervals.h"

#include <map>

namespace rad {

void writeTextureIntervals(const std::string& path, const TextureIntervals& iv,
                           const Provenance& provenance, const nlohmann::json& metadata) {
  ContainerWriter w(kTextureIntervalsKind, kTextureIntervalsMajor, kTextureIntervalsMinor);
  w.setProvenance(provenance);
  w.metadata() = metadata.is_object() ? metadata : nlohmann::json::object();
  w.metadata()["first_frame"] = iv.firstFrame;
  w.metadata()["last_frame"] = iv.lastFrame;
  w.metadata()["fps"] = iv.fps;
  w.metadata()["image_width"] = iv.imageWidth;
  w.metadata()["image_height"] = iv.imageHeight;
  if (!iv.sampling.filter.isNone()) {  // absent: the pixel centres, as in 1.0 files
    w.metadata()["pixel_filter"] = pixelFilterNames().name(iv.sampling.filter.type);
    w.metadata()["filter_width"] = iv.sampling.filter.width;
    w.metadata()["pixel_samples"] = iv.sampling.samplesPerAxis;
  }
  w.metadata()["close_reasons"] = {"left_frustum", "hidden",     "level_change",
                                   "resize",       "max_length", "window"};
  size_t n = iv.movies.size();
  std::vector<uint64_t> patch(n);
  std::vector<int32_t> frames(n * 2), size(n * 2);
  std::vector<uint8_t> reason(n);
  for (size_t i = 0; i < n; ++i) {
    const MovieExtent& m = iv.movies[i];
    if (m.movie != i) throw Error(ExitCode::kInternal, path, "movie ids are not 0..n-1 in order");
    patch[i] = m.patch.packed();
    frames[2 * i] = m.firstFrame;
    frames[2 * i + 1] = m.lastFrame;
    size[2 * i] = m.width;
    size[2 * i + 1] = m.height;
    reason[i] = uint8_t(m.end);
  }
  w.addArray("movie_patch", patch);
  w.addArray("movie_frames", frames, {n, 2});
  w.addArray("movie_size", size, {n, 2});
  w.addArray("movie_close_reason", reason);
  w.write(path);
}

TextureIntervals readTextureIntervals(const ContainerReader& r) {
  const std::string& where = r.path();
  r.requireKind(kTextureIntervalsKind, kTextureIntervalsMajor);
  TextureIntervals iv;
  const nlohmann::json& md = r.metadata();
  try {
    iv.firstFrame = md.at("first_frame").get<int>();
    iv.lastFrame = md.at("last_frame").get<int>();
    iv.fps = md.at("fps").get<double>();
    iv.imageWidth = md.at("image_width").get<int>();
    iv.imageHeight = md.at("image_height").get<int>();
    if (md.contains("pixel_filter")) {  // 1.1
      const std::optional<PixelFilterType> type =
          pixelFilterNames().find(md.at("pixel_filter").get<std::string>());
      if (!type) throw inputError(where, "metadata: unknown pixel_filter");
      iv.sampling.filter.type = *type;
      iv.sampling.filter.width = md.at("filter_width").get<double>();
      iv.sampling.samplesPerAxis = md.at("pixel_samples").get<int>();
      try {
        iv.sampling.validate();
      } catch (const Error& e) {
        throw inputError(where, std::string("metadata: invalid pixel sampling: ") + e.what());
      }
    }
  } catch (const nlohmann::json::exception& e) {
    throw inputError(where, std::string("metadata: ") + e.what());
  }
  if (iv.firstFrame > iv.lastFrame || !(iv.fps > 0) || iv.imageWidth < 1 || iv.imageHeight < 1)
    throw inputError(where, "metadata: invalid window, fps or image size");
  std::vector<uint64_t> patch = r.array<uint64_t>("movie_patch");
  std::vector<int32_t> frames = r.array<int32_t>("movie_frames");
  std::vector<int32_t> size = r.array<int32_t>("movie_size");
  std::vector<uint8_t> reason = r.array<uint8_t>("movie_close_reason");
  size_t n = patch.size();
  if (frames.size() != 2 * n || size.size() != 2 * n || reason.size() != n)
    throw inputError(where, "movie arrays differ in length");
  iv.movies.resize(n);
  for (size_t i = 0; i < n; ++i) {
    MovieExtent& m = iv.movies[i];
    m.movie = uint32_t(i);
    m.patch = PatchId::fromPacked(patch[i]);
    if (m.patch.path == 0 || m.patch.level() > PatchId::kMaxLevel)
      throw inputError(where, "movie " + std::to_string(i) + ": invalid patch id");
    m.firstFrame = frames[2 * i];
    m.lastFrame = frames[2 * i + 1];
    m.width = size[2 * i];
    m.height = size[2 * i + 1];
    if (m.firstFrame > m.lastFrame || m.firstFrame < iv.firstFrame || m.lastFrame > iv.lastFrame)
      throw inputError(where, "movie " + std::to_string(i) + ": frames outside the window");
    if (m.width < 1 || m.height < 1 || m.width > 16384 || m.height > 16384)
      throw inputError(where, "movie " + std::to_string(i) + ": invalid texture size");
    if (reason[i] >= kMovieEndCount)
      throw inputError(where, "movie " + std::to_string(i) + ": unknown close reason");
    m.end = MovieEnd(reason[i]);
  }
  return iv;
}

TextureIntervals readTextureIntervals(const std::string& path) {
  return readTextureIntervals(ContainerReader::open(path));
}

nlohmann::json summarizeTextureIntervals(const ContainerReader& r) {
  TextureIntervals iv = readTextureIntervals(r);
  nlohmann::json j;
  size_t n = iv.movies.size();
  double frames = 0, texels = 0;
  std::map<int, int> levels;
  int reasons[kMovieEndCount] = {};
  for (const MovieExtent& m : iv.movies) {
    frames += m.frameCount();
    texels += double(m.width) * m.height * m.frameCount();
    levels[m.level()]++;
    reasons[int(m.end)]++;
  }
  int window = iv.lastFrame - iv.firstFrame + 1;
  j["window"] = {{"first_frame", iv.firstFrame}, {"last_frame", iv.lastFrame}, {"fps", iv.fps}};
  j["movies"] = n;
  j["mean_length_frames"] = n ? frames / n : 0.0;
  j["texels_per_frame"] = texels / window;
  nlohmann::json lv = nlohmann::json::object();
  for (auto& [l, c] : levels) lv[std::to_string(l)] = c;
  j["movies_per_level"] = lv;
  nlohmann::json rs = nlohmann::json::object();
  for (int k = 0; k < kMovieEndCount; ++k) rs[movieEndName(MovieEnd(k))] = reasons[k];
  j["close_reasons"] = rs;
  return j;
}

}  // namespace rad
