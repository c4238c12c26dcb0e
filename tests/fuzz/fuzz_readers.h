// Each reader as its fuzz harness feeds it bytes: shared by the libFuzzer harnesses
// (fuzz_<reader>.cpp, clang) and the regression replay (tests/format/fuzz_regressions_test.cpp,
// the normal build), so a committed reproducer is replayed through exactly the calls that
// crashed. Every feed returns normally on success or rad::Error; anything else escapes.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "formats/container.h"
#include "formats/exr_image.h"
#include "formats/exr_info.h"
#include "formats/frame_image.h"
#include "formats/gltf_scene.h"
#include "formats/inspect_kinds.h"
#include "formats/key_window.h"
#include "formats/link_hierarchy.h"
#include "formats/texture_intervals.h"
#include "formats/texture_movie.h"
#include "libcommon/scene/scene_summary.h"
#include "tests/fuzz/fuzz_reseal.h"
#include "tests/fuzz/fuzz_support.h"

namespace rad::fuzz {

// The glTF seeds' external buffers and images (cornell_box.bin, l.jpg, ...) beside the scene
// file, so a mutated seed still reaches its accessors instead of stopping at a missing .bin.
inline void copyGltfSidecars(const std::string& sourceDir) {
  namespace fs = std::filesystem;
  for (const auto& e : fs::recursive_directory_iterator(sourceDir + "/tests/data/external")) {
    const std::string ext = e.path().extension().string();
    if (e.is_regular_file() && (ext == ".bin" || ext == ".jpg" || ext == ".png"))
      fs::copy_file(e.path(), fs::path(scratchDir()) / e.path().filename(),
                    fs::copy_options::overwrite_existing);
  }
}

// .gltf JSON or .glb (readGltfScene detects the binary form by its magic, whatever the
// extension), then rad-inspect's scene summary.
inline void feedGltf(const uint8_t* data, size_t size) {
  const std::string path = writeScratch("scene.gltf", data, size);
  runReader([&] { (void)summarizeScene(readGltfScene(path)); });
}

// Raw bytes as a container, then what rad-inspect prints of one: the summary and the kind's
// content summary (summarizeContainerContent, as rad-inspect calls it).
inline void feedContainer(const uint8_t* data, size_t size) {
  runReader([&] {
    const ContainerReader reader =
        ContainerReader::fromBytes(std::vector<uint8_t>(data, data + size), "fuzz.rad");
    (void)reader.summary();
    (void)summarizeContainerContent(reader).dump();
  });
}

// The bundled scene, which the seeds of the link hierarchy and key window harnesses were
// computed for (tests/fuzz/make_seeds.sh), read once.
inline const Scene& bundledScene() {
  static const Scene s = readGltfScene(RAD_SOURCE_DIR "/pipelines/scenes/cornell-moving.gltf");
  return s;
}

// A global.rlh with re-sealed checksums (fuzz_reseal.h) against `scene`, the one its seeds were
// computed for, as rad-movies (readLinkHierarchy), rad-compose (readLinkHierarchyRadiosity) and
// rad-inspect (summarizeLinkHierarchy) read it.
inline void feedLinkHierarchy(const uint8_t* data, size_t size, const Scene& scene) {
  runReader([&] {
    const ContainerReader reader =
        ContainerReader::fromBytes(resealContainer(data, size), "fuzz.rlh");
    runReader([&] { (void)summarizeLinkHierarchy(reader); });
    runReader([&] { (void)readLinkHierarchyRadiosity(reader, scene); });
    (void)readLinkHierarchy(reader, scene);
  });
}

// A key window file (rad-global --window) with re-sealed checksums against `scene`, the one its
// seeds were computed for, as rad-global --merge (readKeyWindow) and rad-inspect
// (summarizeKeyWindow) read it.
inline void feedKeyWindow(const uint8_t* data, size_t size, const Scene& scene) {
  runReader([&] {
    const ContainerReader reader =
        ContainerReader::fromBytes(resealContainer(data, size), "fuzz.rkw");
    runReader([&] { (void)summarizeKeyWindow(reader).dump(); });
    (void)readKeyWindow(reader, scene);
  });
}

// An intervals.rti with re-sealed checksums, as rad-movies and rad-compose
// (readTextureIntervals) and rad-inspect (summarizeTextureIntervals) read it.
inline void feedIntervals(const uint8_t* data, size_t size) {
  runReader([&] {
    const ContainerReader reader =
        ContainerReader::fromBytes(resealContainer(data, size), "fuzz.rti");
    runReader([&] { (void)summarizeTextureIntervals(reader); });
    (void)readTextureIntervals(reader);
  });
}

// A texture movie (multi-part EXR) read whole (rad-inspect, tests) and as rad-compose streams
// it (every key through textureAt); and as rad-movies --merge-pieces reads a piece of one
// (formats/texture_movie_piece.md: every key).
inline void feedTextureMovie(const uint8_t* data, size_t size) {
  const std::string path = writeScratch("000000.exr", data, size);
  runReader([&] { (void)readTextureMovie(path); });
  runReader([&] {
    TextureMovieStream stream(path);
    std::vector<float> texels;
    const std::vector<double> times = stream.movie().keyTimes;
    for (double t : times) stream.textureAt(t, texels);
  });
  runReader([&] {
    TextureMovieStream piece(path, MovieFileKind::kPiece);
    for (size_t k = 0; k < piece.movie().keyTimes.size(); ++k) (void)piece.key(k);
  });
}

// A frame EXR as the tests and rad-compose (readFrameExr), rad-diff (readExrImage) and
// rad-inspect (readExrInfo) read it.
inline void feedFrame(const uint8_t* data, size_t size) {
  const std::string path = writeScratch("0000.exr", data, size);
  runReader([&] { (void)readFrameExr(path); });
  runReader([&] { (void)readExrImage(path); });
  runReader([&] { (void)readExrInfo(path); });
}

}  // namespace rad::fuzz
