#include "libcommon/movies/movies_options.h"

namespace rad {

namespace {

using Group = ParameterGroup;
using Check = ParameterCheck;
using O = TextureMovieBakerOptions;

// The knobs of the final preset, and the samples of the bad links' shadows.
void addSampleParameters(ParameterTable<O>& t) {
  t.add("movie-key-step", &O::keyStep, "frames between key textures of a movie", Check::positive(),
        Group::kQuality);
  t.add("min-samples", &O::minSamples,
        "shooter samples per bad link, at least (at most --max-samples)", Check{}, Group::kQuality);
  t.add("near-shooter-levels", &O::nearShooterLevels,
        "gather: split a near leaf shooter into up to 4^L cells, each with its radiosity "
        "re-gathered at its centre from the leaf's links, 0..3 (0: the leaf's one radiosity)",
        Check{}, Group::kQuality);
  t.add("gather-partial-share", &O::gatherPartialShare,
        "gather: a partly occluded link takes its visibility per texel when B F (1 - V) is at "
        "least this share of what the texel gathers, or when the smaller ones left on their V "
        "would sum to more than 2.5 shares (smaller: more links per texel, slower)",
        Check::range(0.0, 1.0), Group::kQuality);
  t.add("moving-shadow-key-step", &O::movingShadowKeyStep,
        "frames between key textures of a movie whose bad links' shadows move (a moving "
        "blocker in the shaft, or a moving end); 0: --movie-key-step",
        Check::nonNegative());
  t.add("good-layer-key-step", &O::goodLayerKeyStep,
        "frames between the good layer's gathers in a movie keyed more finely (its shadows "
        "move); the keys between interpolate it in time (0: gathered at every key)",
        Check::nonNegative());
  t.add("weak-share", &O::weakShare,
        "a bad link giving less than this share of every texel's direct light takes a quarter "
        "of --min-samples at least (0: off)",
        Check::range(0.0, 1.0));
  t.add("max-samples", &O::maxSamples, "shooter samples per bad link, at most (<= 64)");
  t.add("samples-per-form-factor", &O::samplesPerFormFactor,
        "samples = this x the largest texel-to-shooter form factor (paper §3.1)",
        Check::nonNegative());
  t.addEnum("occlusion-merge", &O::merge, mergeModeNames(),
            "static/dynamic occlusion merge: exact (bit masks ORed), or the approximate max, "
            "sum, independent");
  t.add("ray-cast-budget", &O::rayCastBudget,
        "ray cast a pair's occlusion masks on the CPU while texels x samples is at most this, "
        "else render them with OSMesa; 0: always OSMesa",
        Check::nonNegative());
}

// The good links' gather, memory, and the baselines.
void addGatherParameters(ParameterTable<O>& t) {
  t.addEnum("good-layer", &O::goodLayer, goodLayerNames(),
            "indirect light of the good links: gather (per texel, exact point form factors to "
            "each link's shooter) or gouraud (the global solution's vertex values, paper §3.1)");
  t.add("gather-shooter-ratio", &O::gatherShooterRatio,
        "gather: split a link's shooter into the parts of its sub-tree larger than this times "
        "their distance to the receiver's nearest point (0: no split)",
        Check::nonNegative());
  t.add("gather-rays", &O::gatherRays,
        "gather: shadow rays from each texel to a partly occluded link's shooter, 1..64 (0: "
        "the link's one visibility over its receiver)");
  t.add("cluster-visibility-rays", &O::clusterVisibilityRays,
        "gather: rays from each texel to points on its top's far surfaces, whose open share "
        "against the top's mean scales the cluster light, 0..64 (0: the top's one value)");
  t.add("max-texture-memory", &O::maxTextureMemoryMiB,
        "MiB of working memory per movie: one key's texel buffers plus, per bad shooter of a "
        "static pair, its form factors and static-blocker masks (independent of the number of "
        "keys); a movie that needs more is refused (exit 4). The gather keeps its per-texel "
        "form factors in half of it, else recomputes them per key",
        Check::positive());
  t.addFlag("no-fill-covered", &O::fillCovered, false,
            "leave the texels under a touching solid as they come out (~0) instead of giving "
            "them their exposed neighbours' values (the pixels beside a box's foot interpolate "
            "both)",
            Group::kBaseline);
  t.addFlag("no-coherence", &O::coherence, false,
            "re-render every blocker and recompute every form factor at every key, store every "
            "key (the per-frame baseline)",
            Group::kBaseline);
}

}  // namespace

const EnumNames<MergeMode>& mergeModeNames() {
  static const EnumNames<MergeMode> names = EnumNames<MergeMode>::of(
      {MergeMode::kExact, MergeMode::kMax, MergeMode::kSum, MergeMode::kIndependent},
      mergeModeName);
  return names;
}

const EnumNames<GoodLayer>& goodLayerNames() {
  static const EnumNames<GoodLayer> names =
      EnumNames<GoodLayer>::of({GoodLayer::kGather, GoodLayer::kGouraud}, goodLayerName);
  return names;
}

const ParameterTable<TextureMovieBakerOptions>& moviesParameters() {
  static const ParameterTable<O> table = [] {
    ParameterTable<O> t;
    addSampleParameters(t);
    addGatherParameters(t);
    return t;
  }();
  return table;
}

const std::vector<Preset>& moviesPresets() {
  static const std::vector<Preset> presets{
      {"final",
       {{"min-samples", "64"},
        {"movie-key-step", "2"},
        {"near-shooter-levels", "2"},
        {"gather-partial-share", "0.001"}}},
  };
  return presets;
}

nlohmann::json TextureMovieBakerOptions::toJson() const {
  return moviesParameters().toJson(*this);
}

}  // namespace rad
