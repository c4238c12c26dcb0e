// rad-movies' parameters (paper §3.1, §5; docs/design.md §6.3 "rad-movies"), declared once
// (libcommon/core/parameter_table.h): the command line binds each to a field of
// TextureMovieBakerOptions, and TextureMovieBakerOptions::toJson() is the table's provenance.
#pragma once

#include <vector>

#include "libcommon/core/parameter_table.h"
#include "libcommon/movies/texture_movie_baker.h"

namespace rad {

const EnumNames<MergeMode>& mergeModeNames();  // exact, max, sum, independent
const EnumNames<GoodLayer>& goodLayerNames();  // gather, gouraud

const ParameterTable<TextureMovieBakerOptions>& moviesParameters();
// rad-movies' quality presets (README "Recommended settings"): final --min-samples 64
// --movie-key-step 2 --near-shooter-levels 2 --gather-partial-share 0.001; draft and default:
// the struct's values.
const std::vector<Preset>& moviesPresets();

}  // namespace rad
