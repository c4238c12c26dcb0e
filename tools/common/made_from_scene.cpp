#include "tools/common/made_from_scene.h"

#include "libcommon/scene/scene_digest.h"

namespace rad {

void requireMadeFrom(const ContainerReader& reader, const std::string& kind, int major,
                     const Scene& scene) {
  reader.requireKind(kind, major);
  requireSceneDigests(reader.provenance().parameters, reader.path(), reader.provenance().tool,
                      scene);
}

void requireMoviesMadeFrom(const InputRecord& movies, const Scene& scene) {
  if (!movies.history.is_object()) return;
  const Provenance made = Provenance::fromJson(movies.history, movies.path);
  requireSceneDigests(made.parameters, movies.path, made.tool, scene);
}

}  // namespace rad
