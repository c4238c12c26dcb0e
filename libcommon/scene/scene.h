// The scene model: what the toolchain sees of an animated glTF 2.0 scene (docs/design.md §4).
//
// Units are metres and seconds; time is double everywhere. Geometry is kept in each mesh
// node's local frame so motion, rigid or affine (an animated scale), never changes a patch's id
// or (u,v) map; world positions at time t are worldTransform(node, t) applied to the local
// polygons, and world normals and areas come from the placed polygons.
//
// Animation follows the glTF 2.0 specification exactly (§3.11 "Animations"): TRS channels,
// STEP / LINEAR / CUBICSPLINE samplers, shortest-arc normalised slerp for rotations, the
// first key's value held before it and the last key's after it, all animations playing
// together on one clock.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "libcommon/scene/geometry.h"

namespace rad {

// Limits of the scene model, enforced when a scene is read (formats/gltf_scene.md "Limits").
// World coordinates (vertices, node and camera positions, at every time): Embree asserts on
// rays whose origin or direction exceeds ~1.8e18, and areas (squares) must stay finite.
constexpr double kMaxCoordinate = 1e15;
// Exitant radiance L_e per channel, W m^-2 sr^-1 (the sun's disc is ~2e7): emitted power
// pi L_e A and the radiosity B_e / (1 - rho) stay finite, also in float32 outputs.
constexpr double kMaxEmission = 1e12;
// Diffuse reflectance per channel: the radiosity solve converges like rho^n, so rho = 1 with any
// emission diverges; 0.999 is the furnace's highest (docs/design.md §8).
constexpr double kMaxReflectance = 0.999;

struct Texture {
  std::string name;
  int width = 0, height = 0;
  std::vector<float> rgb;  // linear RGB, row-major, 3 floats per texel (sRGB decoded)
  glm::dvec3 mean{1.0};    // mean linear RGB over the texture
};

struct Material {
  std::string name;
  int gltfIndex = -1;  // the material's index in the glTF file (messages name it by both)
  // Diffuse reflectance rho = baseColorFactor.rgb x mean(baseColorTexture), each in
  // [0, kMaxReflectance] when read from a file.
  glm::dvec3 reflectance{1.0};
  // Exitant radiance L_e = emissiveFactor x KHR_materials_emissive_strength, W/(m^2 sr).
  // Emitted radiosity is B_e = pi L_e.
  glm::dvec3 emission{0.0};
  bool doubleSided = false;
  int baseColorTexture = -1;  // index into Scene::textures or -1
  int baseColorTexCoord = 0;
  // emissiveTexture (index into Scene::textures or -1): L_e varies as emission x texture
  // (libcommon/scene/emission_texture.h).
  int emissiveTexture = -1;
  int emissiveTexCoord = 0;

  bool isEmitter() const { return emission.x > 0.0 || emission.y > 0.0 || emission.z > 0.0; }
};

// One triangle of a mesh in its node's local frame, CCW about the front face.
struct MeshTriangle {
  std::array<glm::dvec3, 3> p{};
  std::array<glm::dvec2, 3> uv{};  // TEXCOORD_n of the material's base colour, or zero
  // glTF NORMAL at the vertices (unit, local frame), the shading normal; zero: flat (none).
  std::array<glm::dvec3, 3> normal{};
  int material = -1;  // index into Scene::materials (-1 = glTF default material)
};

struct Mesh {
  std::string name;
  std::vector<MeshTriangle> triangles;  // degenerate (zero-area) triangles already dropped
};

struct Camera {
  std::string name;
  bool perspective = true;
  double yfov = 0.8;              // radians (perspective)
  double aspectRatio = 0.0;       // 0 = take the image's aspect ratio
  double xmag = 1.0, ymag = 1.0;  // orthographic half extents
  double znear = 0.01;
  double zfar = 0.0;  // 0 = infinite (perspective only)
};

// A punctual light (glTF KHR_lights_punctual), in the light's node frame: at the node's origin,
// shining down the node's -Z (spot, directional). Its values are in the renderer's radiometric
// units after the file's units were converted (formats/gltf_scene.md "Lights"; docs/design.md
// §4 "Lights"): W/sr for a point or spot, W/m^2 for a directional light, on the scale of
// Material::emission's W/(m^2 sr).
enum class PunctualLightType { kPoint, kSpot, kDirectional };
// How a spot's intensity falls off from its axis. kGltf: the extension's recommended smooth
// falloff, $t^2$ with $t$ = clamp((cos a - cos outer) / (cos inner - cos outer), 0, 1). kCycles:
// Blender Cycles' spot lamp (its spot_light_attenuation, before Blender 4), what a Blender export
// looks like in Blender: $\cos a \cdot \mathrm{smoothstep}((\cos a - \cos outer) / s)$ inside the
// outer cone, $s = (1 - \cos outer) \cdot blend$, blend = 1 - inner / outer (the inverse of the
// exporter's inner = outer (1 - blend)).
enum class SpotProfile { kGltf, kCycles };

struct PunctualLight {
  std::string name;
  PunctualLightType type = PunctualLightType::kPoint;
  // colour x intensity: radiant intensity I, W/sr (point, spot: on the axis), or irradiance E,
  // W/m^2 on a surface facing the light (directional).
  glm::dvec3 intensity{0.0};
  double range = 0.0;           // metres; 0: infinite (else the extension's recommended window)
  double innerConeAngle = 0.0;  // radians, spot only, < outerConeAngle
  double outerConeAngle = 0.78539816339744830962;  // radians, spot only, in (0, pi/2]
  SpotProfile profile = SpotProfile::kGltf;

  bool emits() const { return intensity.x > 0.0 || intensity.y > 0.0 || intensity.z > 0.0; }
};

struct Node {
  std::string name;
  int parent = -1;
  std::vector<int> children;
  int mesh = -1;    // index into Scene::meshes or -1
  int camera = -1;  // index into Scene::cameras or -1
  int light = -1;   // index into Scene::lights or -1
  // Rest pose (used where no channel animates a property).
  glm::dvec3 translation{0.0};
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};  // glm order (w, x, y, z)
  glm::dvec3 scale{1.0};
};

enum class AnimationPath { kTranslation, kRotation, kScale };
enum class Interpolation { kStep, kLinear, kCubicSpline };

struct AnimationChannel {
  std::string animation;  // name of the glTF animation it came from
  int node = -1;
  AnimationPath path = AnimationPath::kTranslation;
  Interpolation interpolation = Interpolation::kLinear;
  std::vector<double> times;  // strictly increasing key times, seconds
  // Output values, flattened: 3 (T, S) or 4 (R, x y z w as in glTF) doubles per element;
  // CUBICSPLINE has 3 elements per key: in-tangent, value, out-tangent.
  std::vector<double> values;
};

// A camera placed in the world at some time.
struct CameraView {
  Camera lens;
  glm::dmat4 worldFromCamera{1.0};  // rigid (scale removed); camera looks down its -Z, +Y up
  glm::dvec3 eye() const { return glm::dvec3(worldFromCamera[3]); }
};

// A top-level patch: an input polygon in its mesh node's local frame.
struct InputPolygon {
  Polygon local;
  std::array<glm::dvec2, 4> uv{};  // texture coordinates at the vertices
  // Shading normals at the vertices (glTF NORMAL, local frame); zero: flat. Only the per-texel
  // and per-pixel terms use them (rad-movies, rad-reference); the polygon stays the flat
  // radiosity element.
  std::array<glm::dvec3, 4> normal{};
  int node = -1;  // mesh node that places it in the world
  int material = -1;
  bool backFace = false;  // the reversed copy made for a doubleSided material
  // Its mesh is a closed solid with faces out (closed_solid.h), so its winding tells inside from
  // outside even when the material is doubleSided.
  bool closedSolid = false;
};

// The shading normal of `p` at its (u,v) (the vertex normals interpolated with the weights of
// polygonPointAt, normalised), in its local frame; the flat normal when it has none, or when
// the interpolation degenerates or faces away from the flat normal's side.
glm::dvec3 shadingNormalAt(const InputPolygon& p, glm::dvec2 uv);

class Scene {
 public:
  std::string path;  // file it was read from (for messages)
  std::vector<Node> nodes;
  std::vector<int> roots;  // root nodes of the displayed scene (empty: every parentless node)
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  std::vector<Texture> textures;
  std::vector<Camera> cameras;
  std::vector<AnimationChannel> channels;
  std::vector<std::string> warnings;  // e.g. "dropped 3 zero-area triangles"
  std::vector<PunctualLight> lights;  // KHR_lights_punctual, placed by Node::light
  // The units the lights were read in: "gltf" or "blender" (formats/gltf_scene.md "Lights").
  std::string lightUnits = "gltf";

  // Local transform of a node at time t with glTF semantics (T * R * S).
  glm::dmat4 localTransform(int node, double t) const;
  // World transform: product of local transforms from the root down.
  glm::dmat4 worldTransform(int node, double t) const;

  // Time range covered by the animation keys; both 0 for a static scene.
  double startTime() const;
  double endTime() const;
  double duration() const { return endTime() - startTime(); }

  // Nodes reachable from roots (or from every parentless node when roots is empty),
  // in ascending index order.
  std::vector<int> reachableNodes() const;
  // Nodes that carry a mesh and are reachable from roots, in ascending index order.
  std::vector<int> meshNodes() const;
  // True when the node's world transform changes somewhere in [t0, t1].
  bool isDynamic(int node, double t0, double t1) const;
  // Whether the polygon's material emits (false without a material).
  bool emits(const InputPolygon& p) const {
    return p.material >= 0 && size_t(p.material) < materials.size() &&
           materials[size_t(p.material)].isEmitter();
  }
  // World-space axis-aligned bounds swept by a mesh node's geometry over [t0, t1]:
  // {min, max}. Conservative (exact for static nodes).
  // Static nodes: bounds of the transformed vertices. Dynamic nodes: the 8 corners of the
  // local box at sampleTimes(node, t0, t1, 32), padded by the largest distance a corner moves
  // between consecutive samples (conservative while the path between two samples is at most
  // twice as long as its chord, which dense sampling of glTF curves guarantees in practice).
  std::array<glm::dvec3, 2> sweptBounds(int node, double t0, double t1) const;
  // Sorted distinct times in [t0, t1]: 65 uniform samples, plus perSegment + 1 samples over
  // every key segment of the channels animating the node or its ancestors (and the instant
  // before each key, where STEP jumps).
  std::vector<double> sampleTimes(int node, double t0, double t1, int perSegment) const;

  // Top-level patches of all mesh nodes: triangles, with coplanar adjacent pairs that form a
  // convex parallelogram (to 5 % of its size) merged; a triangle's corners rotated so that v0 is
  // opposite its longest edge (docs/design.md §4); doubleSided materials add a reversed copy.
  // Deterministic order: by mesh node, then triangle order.
  std::vector<InputPolygon> inputPolygons() const;

  // Nodes that carry a light that emits and are reachable from roots, in ascending index order.
  std::vector<int> lightNodes() const;

  // Camera nodes reachable from roots, in ascending index order. cameraNode("") is the first;
  // cameraNode(name) matches a node name first, then a camera name; -1 if none.
  std::vector<int> cameraNodes() const;
  int cameraNode(const std::string& name) const;
  CameraView cameraAt(int node, double t) const;
};

// Empty when a mesh of the displayed scene has an emitting material or a light node of it
// emits; else what is missing, on one line.
std::string missingEmitterMessage(const Scene& scene);
// Throws rad::Error (kBadInput) `path: missingEmitterMessage` when there is no emitter: a tool
// that computes light would render black frames.
void requireEmitter(const Scene& scene);

// The distinct mesh nodes of `polygons` that move somewhere in [t0, t1] (Scene::isDynamic),
// in first-appearance order.
std::vector<int> movingNodesOf(const Scene& scene, const std::vector<InputPolygon>& polygons,
                               double t0, double t1);

}  // namespace rad
