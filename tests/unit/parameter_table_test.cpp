// libcommon/core/parameter_table.h and the stages' tables: names once, enum names that parse
// back, presets that name parameters the stage has, provenance keys as before the tables.
#include "libcommon/core/parameter_table.h"

#include <gtest/gtest.h>

#include "libcommon/compose/compose_options.h"
#include "libcommon/intervals/intervals_options.h"
#include "libcommon/movies/movies_options.h"
#include "libcommon/radiosity/global_stage.h"
#include "libcommon/reference/reference_options.h"

namespace rad {
namespace {

template <class E>
void expectRoundTrip(const EnumNames<E>& names) {
  for (const std::string& n : names.names()) EXPECT_EQ(names.name(names.parse(n, "--x")), n);
  EXPECT_THROW(names.parse("nonsense", "--x"), Error);
}

TEST(ParameterTable, EnumNamesRoundTrip) {
  expectRoundTrip(mergeModeNames());
  expectRoundTrip(goodLayerNames());
  for (const auto* table : {&globalParameters()})
    for (const auto& p : table->entries())
      for (const std::string& c : p.choices) {
        GlobalOptions g;
        p.set(g, c);
        EXPECT_EQ(p.value(g), c) << p.name;
      }
}

// The provenance keys rad-global recorded before its table (global.rlh's metadata holds them:
// a change of key set changes the file).
TEST(ParameterTable, GlobalProvenanceKeysAreUnchanged) {
  const nlohmann::json json = GlobalOptions{}.toJson();
  std::vector<std::string> keys;
  for (const auto& [k, v] : json.items()) keys.push_back(k);
  EXPECT_EQ(keys, (std::vector<std::string>{"bad-links",
                                            "cluster-member-rays",
                                            "cluster-separation",
                                            "eps",
                                            "fps",
                                            "frames",
                                            "isotropic-clusters",
                                            "key-step",
                                            "light-cluster-share",
                                            "max-links",
                                            "min-area",
                                            "near-block-rays",
                                            "no-closed-rooms",
                                            "no-closure",
                                            "no-clustering",
                                            "no-coherence",
                                            "no-shooter-shape",
                                            "oracle",
                                            "partial-power-share",
                                            "partial-threshold",
                                            "rays",
                                            "refine-weak-near-links",
                                            "shadow-eps-share",
                                            "tol",
                                            "weak-near-ambient-share"}));
  EXPECT_EQ(GlobalOptions{}.toJson().at("no-coherence"), false);
  EXPECT_EQ(GlobalOptions{}.toJson().at("oracle"), "both");
}

template <class O>
void expectPresetsApply(const ParameterTable<O>& table, const std::vector<Preset>& presets) {
  for (const Preset& p : presets) {
    O o;
    EXPECT_NO_THROW(table.apply(o, p.values)) << p.name;
    EXPECT_NE(table.toJson(o), table.toJson(O{})) << p.name << " sets nothing";
    EXPECT_NO_THROW(table.validate(o)) << p.name;
  }
}

TEST(ParameterTable, PresetsSetParametersTheStageHas) {
  expectPresetsApply(globalParameters(), globalPresets());
  expectPresetsApply(moviesParameters(), moviesPresets());
  expectPresetsApply(intervalsParameters(), intervalsPresets());
  expectPresetsApply(composeParameters(), composePresets());
  EXPECT_EQ(findPreset(globalPresets(), "default").values.size(), 0u);
  EXPECT_THROW(findPreset(globalPresets(), "best"), Error);
  GlobalOptions g;
  globalParameters().apply(g, findPreset(globalPresets(), "final").values);
  EXPECT_EQ(g.spaceTime.radiosity.eps, 1e-5);
  EXPECT_EQ(g.keyStep, 4);
  EXPECT_EQ(g.spaceTime.radiosity.rays, 64);
}

TEST(ParameterTable, ValidateNamesTheFlag) {
  GlobalOptions g;
  EXPECT_NO_THROW(globalParameters().validate(g));
  g.spaceTime.radiosity.eps = -1;
  try {
    globalParameters().validate(g);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::kUsage);
    EXPECT_NE(std::string(e.what()).find("--eps -1.0 is not a finite number >= 0"),
              std::string::npos)
        << e.what();
  }
  EXPECT_NO_THROW(intervalsParameters().validate(IntervalsOptions{}));
  EXPECT_NO_THROW(composeParameters().validate(ComposeOptions{}));
  EXPECT_NO_THROW(referenceParameters().validate(ReferenceOptions{}));
  EXPECT_NO_THROW(moviesParameters().validate(TextureMovieBakerOptions{}));
}

TEST(ParameterTable, ANameIsDeclaredOnce) {
  struct O {
    int a = 0;
  };
  ParameterTable<O> t;
  t.add("a", &O::a, "a");
  EXPECT_THROW(t.add("a", &O::a, "again"), Error);
}

}  // namespace
}  // namespace rad
