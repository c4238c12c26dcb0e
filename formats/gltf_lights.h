// KHR_lights_punctual read into the scene model's lights (spec: formats/gltf_scene.md "Lights";
// docs/design.md §4 "Lights"): the lights' colour x intensity converted to the renderer's units,
// spot cones and range checked, and each node's light index.
#pragma once

#include <string>

#include "libcommon/scene/scene.h"

namespace tinygltf {
class Model;
}

namespace rad {

// How the file's light intensities become the renderer's radiometric units (W/sr, W/m^2, on the
// scale of an emissive material's radiance):
//  * kGltf: as the extension says, candela and lux taken as W/sr and W/m^2 alike (an emissive
//    strength in nits is taken as W/(m^2 sr) too, so lamps and emitting surfaces keep their
//    ratio);
//  * kBlender: as Blender's exporter wrote them (its default "Standard" lighting mode): a lamp of
//    P watts is P / (4 pi) x 683 cd and a sun of S W/m^2 is S x 683 lux while emission strength
//    is written unchanged, so intensities are divided by 683 and spots take Cycles' profile
//    (SpotProfile::kCycles): the scene renders as Blender renders it;
//  * kAuto: kBlender when asset.generator names Blender's exporter ("Khronos glTF Blender I/O"),
//    else kGltf.
enum class LightUnits { kAuto, kGltf, kBlender };

// Watts per lumen at 555 nm, the factor Blender's exporter applies (PBR_WATTS_TO_LUMENS).
constexpr double kBlenderLumensPerWatt = 683.0;

// "auto", "gltf", "blender".
std::string lightUnitsName(LightUnits units);
// Throws std::invalid_argument for another name.
LightUnits parseLightUnits(const std::string& name);
// kAuto resolved from the file's asset.generator.
LightUnits resolveLightUnits(LightUnits units, const std::string& generator);

// Fills scene.lights (one per KHR_lights_punctual light, in file order), scene.lightUnits and
// Node::light of scene.nodes (which must be read already). Throws rad::Error (kBadInput) `path:
// light N: what` for an unknown type, a colour that is not 3 finite values in [0, inf), an
// intensity that is negative, non-finite or beyond kMaxEmission after conversion, a negative
// range, spot cones outside 0 <= inner < outer <= pi/2, and `node N: light M out of range`.
void readPunctualLights(const std::string& path, const tinygltf::Model& model, LightUnits units,
                        Scene& scene);

}  // namespace rad
