// What rad.pixelChecksum costs (issue 18): writing and reading a texture movie and a frame,
// against the checksum's own time over the same pixels. Usage:
//   exr_checksum_bench [W H KEYS REPEATS]   (default 64 64 8 200: a 393 KB movie, about the
//   table scene's mean of 171 KB per movie rounded up; frames at rad-compose's 352x240)
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>

#include "formats/frame_image.h"
#include "formats/pixel_checksum.h"
#include "formats/texture_movie.h"

namespace {

double secondsPer(int repeats, const std::function<void()>& f) {
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < repeats; ++i) f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / repeats;
}

}  // namespace

int main(int argc, char** argv) {
  const int w = argc > 1 ? std::atoi(argv[1]) : 64, h = argc > 2 ? std::atoi(argv[2]) : 64;
  const int keys = argc > 3 ? std::atoi(argv[3]) : 8, repeats = argc > 4 ? std::atoi(argv[4]) : 200;
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("rad_exr_checksum_bench_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  rad::TextureMovie m;
  m.movie = 1;
  m.patch = rad::PatchId{1, 1};
  m.width = w;
  m.height = h;
  m.lastFrame = 6 * (keys - 1);
  for (int k = 0; k < keys; ++k) {
    m.keyFrames.push_back(6 * k);
    m.keyTimes.push_back(6 * k / 24.0);
    m.keys.emplace_back(size_t(w) * h * 3);
    for (size_t i = 0; i < m.keys.back().size(); ++i)
      m.keys.back()[i] = 0.1f * float(k + 1) + 1e-4f * float(i % 9973);
  }
  const std::string movie = rad::textureMoviePath(dir.string(), 1);
  const double write = secondsPer(repeats, [&] { rad::writeTextureMovie(movie, m); });
  const double read = secondsPer(repeats, [&] { rad::readTextureMovie(movie); });
  const double stream = secondsPer(repeats, [&] {
    rad::TextureMovieStream s(movie);
    for (int k = 0; k < keys; ++k) s.key(size_t(k));
  });
  const double checksum = secondsPer(repeats, [&] {
    for (const auto& key : m.keys) rad::rgbPixelChecksum(key.data(), w, h);
  });
  std::printf(
      "movie %dx%d, %d keys, %ju bytes: write %.3f ms, readTextureMovie %.3f ms, "
      "TextureMovieStream (every key) %.3f ms; checksums of its pixels %.3f ms (%.2f "
      "ns/byte)\n",
      w, h, keys, std::uintmax_t(std::filesystem::file_size(movie)), 1e3 * write, 1e3 * read,
      1e3 * stream, 1e3 * checksum, 1e9 * checksum / (double(keys) * w * h * 12));

  rad::ComposedFrame f;
  f.size = {352, 240};
  f.rgb.resize(size_t(352) * 240 * 3);
  for (size_t i = 0; i < f.rgb.size(); ++i) f.rgb[i] = 1e-3f * float(i % 4099);
  const std::string frame = rad::framePath(dir.string(), 1, ".exr");
  rad::FrameImageInfo info;
  const double fwrite = secondsPer(repeats, [&] { rad::writeFrameExr(frame, f, info, false); });
  const double fread = secondsPer(repeats, [&] { rad::readFrameExr(frame); });
  const double fsum = secondsPer(repeats, [&] { rad::rgbPixelChecksum(f.rgb.data(), 352, 240); });
  std::printf(
      "frame 352x240 FLOAT: writeFrameExr %.3f ms, readFrameExr %.3f ms; checksum of "
      "its pixels %.3f ms\n",
      1e3 * fwrite, 1e3 * fread, 1e3 * fsum);
  std::filesystem::remove_all(dir);
  return 0;
}
