// The check every stage that reads an earlier stage's output makes before using it: the file
// was made from this scene (issue 54: intermediates from a scene with other materials were
// accepted), compared part by part with the digests the producer recorded
// (libcommon/scene/scene_digest.h).
#pragma once

#include <string>

#include "formats/container.h"
#include "libcommon/scene/scene.h"

namespace rad {

// Throws rad::inputError(reader.path(), ...) when the file is not of `kind` with major version
// `major` (ContainerReader::requireKind), or when a part of the scene it was made from
// differs from `scene`'s: `made from a scene whose materials differ (...); re-run rad-global`.
void requireMadeFrom(const ContainerReader& reader, const std::string& kind, int major,
                     const Scene& scene);

// The same for a movies folder, by the history addMoviesInput recorded (the first movie's
// provenance; every movie of a run carries the same). Nothing to check without one.
void requireMoviesMadeFrom(const InputRecord& movies, const Scene& scene);

}  // namespace rad
