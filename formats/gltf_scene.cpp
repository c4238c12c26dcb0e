// glTF 2.0 scene reader (spec: formats/gltf_scene.md).
//
// Parsing is tinygltf's (Debian libtinygltf, compiled; images decoded by its stb loader).
// Everything it does not check is checked here before any byte is read: accessor and buffer
// view ranges, strides, index ranges, finite values, animation key counts.
// Section numbers cite the glTF 2.0 specification (Khronos, 2.0.1).
#include "formats/gltf_scene.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <new>
#include <sstream>

#include "formats/gltf_message_text.h"
#include "formats/gltf_lights.h"
#include "formats/gltf_scene_file.h"
#include "formats/gltf_triangles.h"
#include "libcommon/core/error.h"
#include "libcommon/scene/gltf_item_label.h"

namespace rad {

namespace {

class Reader {
 public:
  Reader(const std::string& path, const tinygltf::Model& model, const GltfReadOptions& options,
         const GltfLoaderHooks& hooks)
      : path_(path), m_(model), options_(options), hooks_(hooks) {}
  Scene read();

 private:
  [[noreturn]] void fail(const std::string& what) const { throw inputError(path_, what); }

  std::vector<double> readAccessor(int index, const std::string& what, int& components,
                                   bool forceNormalized = false) const;
  void requireFloat(int accessor, const std::string& what) const;
  void readNodes(Scene& scene);
  void readMesh(int meshIndex, Scene& scene);
  void readPrimitive(const tinygltf::Primitive& prim, const std::string& where, Mesh& mesh,
                     Scene& scene);
  std::vector<double> readPositions(const tinygltf::Primitive& prim,
                                    const std::string& where) const;
  std::vector<double> readTexCoords(const tinygltf::Primitive& prim, const Material* mat,
                                    size_t vertexCount, const std::string& where,
                                    Scene& scene) const;
  std::vector<double> readNormals(const tinygltf::Primitive& prim, size_t vertexCount,
                                  const std::string& where) const;
  std::vector<uint32_t> readIndices(const tinygltf::Primitive& prim, size_t vertexCount,
                                    const std::string& where) const;
  int material(int index, Scene& scene);
  void clampReflectance(Material& mat, const std::string& where, Scene& scene) const;
  int texture(int index, Scene& scene);
  void readCameras(Scene& scene);
  void readAnimations(Scene& scene);
  void checkWorldBounds(const Scene& scene) const;
  void requireWorldArea(const Scene& scene, int node, double t) const;

  std::string path_;
  const tinygltf::Model& m_;
  GltfReadOptions options_;
  const GltfLoaderHooks& hooks_;    // why an image has no pixels
  std::map<int, int> materialMap_;  // glTF material -> Scene::materials
  std::map<int, int> textureMap_;   // glTF texture -> Scene::textures
  size_t droppedTriangles_ = 0;
};

bool allFinite(const std::vector<double>& v) {
  return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
}

double readComponent(const unsigned char* p, int componentType, bool normalized) {
  // Little-endian storage (glTF §3.6.2); this reader assumes a little-endian host.
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      int8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? std::max(v / 127.0, -1.0) : v;  // §3.11 "normalized" decoding
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
      uint8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? v / 255.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return normalized ? v / 4294967295.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_INT: {  // not allowed by glTF 2.0 accessors, read anyway
      int32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
    default: {
      double v;
      std::memcpy(&v, p, 8);
      return v;
    }
  }
}

int componentSize(int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_INT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return -1;  // DOUBLE is not glTF 2.0
  }
}

int typeComponents(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return 1;
    case TINYGLTF_TYPE_VEC2:
      return 2;
    case TINYGLTF_TYPE_VEC3:
      return 3;
    case TINYGLTF_TYPE_VEC4:
      return 4;
    case TINYGLTF_TYPE_MAT2:
      return 4;
    case TINYGLTF_TYPE_MAT3:
      return 9;
    case TINYGLTF_TYPE_MAT4:
      return 16;
    default:
      return -1;
  }
}

// The narrowest perspective yfov. The rasterising stages round projection x view x model to
// float once (rasterClipFromLocal): the x, y rows scale with 1 / tan(yfov / 2), so the rounding
// of their translation part, 2^-24 |eye| / tan(yfov / 2), must stay below a pixel of the
// largest image (2 / 16384 in NDC) for a camera about as far from the origin as from what it
// sees: tan(yfov / 2) > 5e-4. A yfov of 1e-9 left most pixels without a surface (black). Real
// lenses stay far above it (a 1200 mm telephoto on 35 mm film: 0.02 rad).
constexpr double kMinYfov = 1e-3;

// Elements of an accessor without a bufferView (zeros but for sparse substitutions).
constexpr size_t kMaxZeroElements = size_t(1) << 20;

// Checks that `count` elements of `elementSize` bytes at `offset` with `stride` fit in a view of
// `viewLength` bytes (no overflow).
bool fits(size_t offset, size_t count, size_t stride, size_t elementSize, size_t viewLength) {
  if (count == 0) return offset <= viewLength;
  if (offset > viewLength || elementSize > viewLength - offset) return false;
  size_t room = viewLength - offset - elementSize;  // bytes left after the first element
  return stride == 0 || (count - 1) <= room / stride;
}

}  // namespace

// Returns count x components doubles (matrices column-major, without padding; glTF §3.6.2.4
// column padding for MAT2/MAT3 of 1-2 byte components is not handled: not used by this reader).
std::vector<double> Reader::readAccessor(int index, const std::string& what, int& components,
                                         bool forceNormalized) const {
  const std::string where = what + ": accessor " + std::to_string(index);
  if (index < 0 || index >= int(m_.accessors.size()))
    fail(what + ": accessor index " + std::to_string(index) + " out of range");
  const tinygltf::Accessor& a = m_.accessors[size_t(index)];
  const int csize = componentSize(a.componentType);
  components = typeComponents(a.type);
  if (csize <= 0) fail(where + ": unsupported component type " + std::to_string(a.componentType));
  if (components <= 0) fail(where + ": unsupported type " + std::to_string(a.type));
  const bool normalized = a.normalized || forceNormalized;
  const size_t elementSize = size_t(csize) * size_t(components);
  // 2^28 elements (> 1 GB of doubles) is far beyond any scene this toolchain handles.
  if (a.count > (size_t(1) << 28))
    fail(where + ": count " + std::to_string(a.count) + " too large");
  auto viewBytes = [&](int viewIndex,
                       const std::string& role) -> std::pair<const unsigned char*, size_t> {
    if (viewIndex < 0 || viewIndex >= int(m_.bufferViews.size()))
      fail(where + ": " + role + "bufferView " + std::to_string(viewIndex) + " out of range");
    const tinygltf::BufferView& v = m_.bufferViews[size_t(viewIndex)];
    if (v.buffer < 0 || v.buffer >= int(m_.buffers.size()))
      fail(where + ": bufferView " + std::to_string(viewIndex) + ": buffer " +
           std::to_string(v.buffer) + " out of range");
    const tinygltf::Buffer& b = m_.buffers[size_t(v.buffer)];
    if (v.byteOffset > b.data.size() || v.byteLength > b.data.size() - v.byteOffset)
      fail(where + ": bufferView " + std::to_string(viewIndex) + " (offset " +
           std::to_string(v.byteOffset) + ", length " + std::to_string(v.byteLength) +
           ") exceeds buffer " + std::to_string(v.buffer) + " of " + std::to_string(b.data.size()) +
           " bytes");
    return {b.data.data() + v.byteOffset, v.byteLength};
  };
  // Every bound is checked before the output is allocated: a count of 2^25 on a 48-byte view would
  // otherwise allocate 800 MB before its error.
  const unsigned char* data = nullptr;
  size_t stride = elementSize;
  if (a.bufferView >= 0) {
    auto [bytes, length] = viewBytes(a.bufferView, "");
    const tinygltf::BufferView& v = m_.bufferViews[size_t(a.bufferView)];
    stride = v.byteStride ? v.byteStride : elementSize;
    if (stride < elementSize)
      fail(where + ": byteStride " + std::to_string(stride) + " smaller than element size " +
           std::to_string(elementSize));
    if (!fits(a.byteOffset, a.count, stride, elementSize, length))
      fail(where + ": " + std::to_string(a.count) + " elements at offset " +
           std::to_string(a.byteOffset) + " exceed bufferView " + std::to_string(a.bufferView) +
           " (" + std::to_string(length) + " bytes)");
    data = bytes + a.byteOffset;
  } else if (a.count > kMaxZeroElements) {
    // Without a bufferView the elements are zeros (glTF section 3.6.2.3) taking no bytes of the
    // file: bounded so that a few bytes of JSON cannot ask for gigabytes.
    fail(where + ": " + std::to_string(a.count) + " elements without a bufferView (limit " +
         std::to_string(kMaxZeroElements) + ")");
  }
  std::vector<double> out(a.count * size_t(components), 0.0);
  for (size_t i = 0; data && i < a.count; ++i) {
    const unsigned char* p = data + i * stride;
    for (int c = 0; c < components; ++c)
      out[i * size_t(components) + size_t(c)] =
          readComponent(p + size_t(c) * size_t(csize), a.componentType, normalized);
  }
  if (a.sparse.isSparse) {  // glTF §3.6.2.3 sparse accessors: substitute the listed elements
    const int n = a.sparse.count;
    if (n < 0 || size_t(n) > a.count)
      fail(where + ": sparse count " + std::to_string(n) + " out of range");
    const int icType = a.sparse.indices.componentType;
    if (icType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        icType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        icType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
      fail(where + ": sparse indices component type " + std::to_string(icType) + " not allowed");
    auto [idata, ilength] = viewBytes(a.sparse.indices.bufferView, "sparse indices ");
    auto [vdata, vlength] = viewBytes(a.sparse.values.bufferView, "sparse values ");
    const size_t isize = size_t(componentSize(icType));
    if (a.sparse.indices.byteOffset < 0 || a.sparse.values.byteOffset < 0 ||
        !fits(size_t(a.sparse.indices.byteOffset), size_t(n), isize, isize, ilength) ||
        !fits(size_t(a.sparse.values.byteOffset), size_t(n), elementSize, elementSize, vlength))
      fail(where + ": sparse data exceeds its bufferView");
    for (size_t k = 0; k < size_t(n); ++k) {
      size_t target = size_t(
          readComponent(idata + size_t(a.sparse.indices.byteOffset) + k * isize, icType, false));
      if (target >= a.count)
        fail(where + ": sparse index " + std::to_string(target) + " out of range");
      const unsigned char* p = vdata + size_t(a.sparse.values.byteOffset) + k * elementSize;
      for (int c = 0; c < components; ++c)
        out[target * size_t(components) + size_t(c)] =
            readComponent(p + size_t(c) * size_t(csize), a.componentType, normalized);
    }
  }
  return out;
}

// glTF 2.0 section 3.7.2.1: POSITION and NORMAL are float; integer ones are quantized data of
// KHR_mesh_quantization (not supported). Read as integers they were garbage geometry: 0..255
// "metres" from a float buffer's bytes.
void Reader::requireFloat(int accessor, const std::string& what) const {
  if (accessor < 0 || accessor >= int(m_.accessors.size())) return;  // readAccessor says so
  const int ct = m_.accessors[size_t(accessor)].componentType;
  if (ct != TINYGLTF_COMPONENT_TYPE_FLOAT)
    fail(what + " has component type " + std::to_string(ct) +
         ", not float (5126); quantized attributes (KHR_mesh_quantization) are not supported");
}

Scene Reader::read() {
  Scene scene;
  scene.path = path_;
  for (const std::string& ext : m_.extensionsRequired)
    if (ext != "KHR_materials_emissive_strength" && ext != "KHR_lights_punctual")
      fail("required extension " + clipInput(ext) + " is not supported");
  for (size_t i = 0; i < m_.nodes.size(); ++i) {
    if (m_.nodes[i].skin >= 0)
      fail(gltfItemLabel("node", int(i), m_.nodes[i].name) +
           " has a skin; skinned meshes are not supported (a node moves as a whole)");
  }
  for (size_t i = 0; i < m_.meshes.size(); ++i)
    for (const tinygltf::Primitive& p : m_.meshes[i].primitives)
      if (!p.targets.empty())
        fail(gltfItemLabel("mesh", int(i), m_.meshes[i].name) +
             " has morph targets; they are not supported (a node moves as a whole)");
  readNodes(scene);
  readPunctualLights(path_, m_, options_.lightUnits, scene);
  scene.meshes.resize(m_.meshes.size());
  for (size_t i = 0; i < scene.meshes.size(); ++i) scene.meshes[i].name = m_.meshes[i].name;
  std::vector<char> needed(m_.meshes.size(), 0);
  for (int n : scene.reachableNodes())
    if (scene.nodes[size_t(n)].mesh >= 0) needed[size_t(scene.nodes[size_t(n)].mesh)] = 1;
  for (size_t i = 0; i < m_.meshes.size(); ++i)
    if (needed[i]) readMesh(int(i), scene);
  if (droppedTriangles_ > 0)
    scene.warnings.push_back("dropped " + std::to_string(droppedTriangles_) +
                             " zero-area triangles");
  readCameras(scene);
  readAnimations(scene);
  checkWorldBounds(scene);
  return scene;
}

void Reader::readNodes(Scene& scene) {
  const size_t count = m_.nodes.size();
  scene.nodes.resize(count);
  for (size_t i = 0; i < count; ++i) {
    const tinygltf::Node& g = m_.nodes[i];
    Node& n = scene.nodes[i];
    const std::string where = gltfItemLabel("node", int(i), g.name);
    n.name = g.name;
    if (g.mesh >= int(m_.meshes.size()))
      fail(where + ": mesh " + std::to_string(g.mesh) + " out of range");
    if (g.camera >= int(m_.cameras.size()))
      fail(where + ": camera " + std::to_string(g.camera) + " out of range");
    n.mesh = g.mesh < 0 ? -1 : g.mesh;
    n.camera = g.camera < 0 ? -1 : g.camera;
    for (int c : g.children) {
      if (c < 0 || c >= int(count)) fail(where + ": child " + std::to_string(c) + " out of range");
      if (scene.nodes[size_t(c)].parent >= 0 || size_t(c) == i)
        fail(where + ": " + gltfItemLabel("node", c, m_.nodes[size_t(c)].name) +
             " has more than one parent (glTF §3.5.2: the hierarchy must be a forest)");
      scene.nodes[size_t(c)].parent = int(i);
      n.children.push_back(c);
    }
    if (!allFinite(g.translation) || !allFinite(g.rotation) || !allFinite(g.scale) ||
        !allFinite(g.matrix))
      fail(where + ": non-finite transform");
    if (g.matrix.size() == 16) {
      // glTF §3.5.3: matrix is column-major and must be decomposable to T * R * S.
      glm::dmat4 mat;
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) mat[c][r] = g.matrix[size_t(c * 4 + r)];
      n.translation = glm::dvec3(mat[3]);
      glm::dmat3 basis(mat);
      glm::dvec3 s(glm::length(basis[0]), glm::length(basis[1]), glm::length(basis[2]));
      if (glm::determinant(basis) < 0.0) s.x = -s.x;
      n.scale = s;
      if (s.x != 0.0 && s.y != 0.0 && s.z != 0.0) {
        glm::dmat3 rot(basis[0] / s.x, basis[1] / s.y, basis[2] / s.z);
        n.rotation = glm::normalize(glm::quat_cast(rot));
        // Shear cannot be represented by T * R * S: refuse rather than approximate.
        glm::dmat3 back = glm::mat3_cast(n.rotation);
        for (int c = 0; c < 3; ++c)
          if (glm::length(back[c] * s[c] - basis[c]) > 1e-5 * std::max(1.0, std::abs(s[c])))
            fail(where + ": matrix is not a translation-rotation-scale (it has shear)");
      }
    } else {
      if (g.translation.size() == 3)
        n.translation = {g.translation[0], g.translation[1], g.translation[2]};
      if (g.rotation.size() == 4) {
        glm::dquat q(g.rotation[3], g.rotation[0], g.rotation[1], g.rotation[2]);
        double len = glm::length(q);
        if (!(len > 0.0)) fail(where + ": zero rotation quaternion");
        n.rotation = q / len;
      }
      if (g.scale.size() == 3) n.scale = {g.scale[0], g.scale[1], g.scale[2]};
    }
  }
  // Cycles: every node must reach a parentless node.
  for (size_t i = 0; i < count; ++i) {
    int k = int(i);
    for (size_t steps = 0; k >= 0; ++steps) {
      if (steps > count) fail(nodeLabel(scene, int(i)) + ": cycle in the node hierarchy");
      k = scene.nodes[size_t(k)].parent;
    }
  }
  // Roots: glTF §3.5.1 the default scene; defaultScene -1 -> scene 0; no scenes -> all roots.
  if (!m_.scenes.empty()) {
    int s = m_.defaultScene;
    if (s >= int(m_.scenes.size())) fail("scene " + std::to_string(s) + " out of range");
    if (s < 0) s = 0;
    for (int r : m_.scenes[size_t(s)].nodes) {
      if (r < 0 || r >= int(count))
        fail("scene " + std::to_string(s) + ": node " + std::to_string(r) + " out of range");
      if (scene.nodes[size_t(r)].parent >= 0)
        fail("scene " + std::to_string(s) + ": node " + std::to_string(r) + " is not a root");
      scene.roots.push_back(r);
    }
  } else {
    for (size_t i = 0; i < count; ++i)
      if (scene.nodes[i].parent < 0) scene.roots.push_back(int(i));
  }
}

void Reader::readMesh(int meshIndex, Scene& scene) {
  const tinygltf::Mesh& gm = m_.meshes[size_t(meshIndex)];
  for (size_t pi = 0; pi < gm.primitives.size(); ++pi)
    readPrimitive(gm.primitives[pi],
                  meshLabel(scene, meshIndex) + " primitive " + std::to_string(pi),
                  scene.meshes[size_t(meshIndex)], scene);
}

// One primitive, in passes: mode, positions, material, texture coordinates, normals, indices,
// then the triangles (formats/gltf_triangles.h).
void Reader::readPrimitive(const tinygltf::Primitive& prim, const std::string& where, Mesh& mesh,
                           Scene& scene) {
  const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
  if (mode == TINYGLTF_MODE_POINTS || mode == TINYGLTF_MODE_LINE ||
      mode == TINYGLTF_MODE_LINE_LOOP || mode == TINYGLTF_MODE_LINE_STRIP) {
    scene.warnings.push_back(where + ": skipped points/lines primitive (mode " +
                             std::to_string(mode) + ")");
    return;
  }
  if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
      mode != TINYGLTF_MODE_TRIANGLE_FAN)
    fail(where + ": unknown primitive mode " + std::to_string(mode));
  const std::vector<double> p = readPositions(prim, where);
  const size_t vertexCount = p.size() / 3;
  const int matIndex = material(prim.material, scene);
  const Material* mat = matIndex >= 0 ? &scene.materials[size_t(matIndex)] : nullptr;
  const std::vector<double> uv = readTexCoords(prim, mat, vertexCount, where, scene);
  const std::vector<double> normals = readNormals(prim, vertexCount, where);
  const std::vector<uint32_t> idx = readIndices(prim, vertexCount, where);
  const auto tris = unrollTriangles(mode, idx, where, scene.warnings);
  droppedTriangles_ += appendTriangles(tris, PrimitiveVertices{p, uv, normals}, matIndex, mesh);
}

std::vector<double> Reader::readPositions(const tinygltf::Primitive& prim,
                                          const std::string& where) const {
  auto pos = prim.attributes.find("POSITION");
  if (pos == prim.attributes.end()) fail(where + ": no POSITION attribute");
  requireFloat(pos->second, where + ": POSITION");
  int nc = 0;
  std::vector<double> p = readAccessor(pos->second, where + " POSITION", nc);
  if (nc != 3) fail(where + ": POSITION is not VEC3");
  if (!allFinite(p)) fail(where + ": non-finite (NaN or Inf) vertex position");
  for (double x : p)
    if (std::abs(x) > kMaxCoordinate)
      fail(where + ": vertex coordinate " + number(x) + " beyond the limit " +
           number(kMaxCoordinate));
  return p;
}

// The base colour texture's TEXCOORD_n, else the emissive texture's; empty without a texture
// (or, with a warning, without the attribute).
std::vector<double> Reader::readTexCoords(const tinygltf::Primitive& prim, const Material* mat,
                                          size_t vertexCount, const std::string& where,
                                          Scene& scene) const {
  std::vector<double> uv;
  if (!mat || (mat->baseColorTexture < 0 && mat->emissiveTexture < 0)) return uv;
  const bool base = mat->baseColorTexture >= 0;  // one set: the base colour's, else emission's
  const int set = base ? mat->baseColorTexCoord : mat->emissiveTexCoord;
  auto tc = prim.attributes.find("TEXCOORD_" + std::to_string(set));
  if (tc == prim.attributes.end()) {
    scene.warnings.push_back(where + ": material has a" + (base ? " base colour" : "n emissive") +
                             " texture but no TEXCOORD_" + std::to_string(set));
    return uv;
  }
  // glTF §3.7.2: TEXCOORD is float or normalized unsigned byte/short.
  const int ct = tc->second >= 0 && tc->second < int(m_.accessors.size())
                     ? m_.accessors[size_t(tc->second)].componentType
                     : TINYGLTF_COMPONENT_TYPE_FLOAT;
  int nc = 0;
  uv = readAccessor(tc->second, where + " TEXCOORD", nc, ct != TINYGLTF_COMPONENT_TYPE_FLOAT);
  if (nc != 2) fail(where + ": TEXCOORD is not VEC2");
  if (uv.size() / 2 != vertexCount) fail(where + ": TEXCOORD count differs from POSITION count");
  if (!allFinite(uv)) fail(where + ": non-finite texture coordinate");
  return uv;
}

// glTF §3.7.2.1: NORMAL is float VEC3, unit length; the shading normal (flat without it).
std::vector<double> Reader::readNormals(const tinygltf::Primitive& prim, size_t vertexCount,
                                        const std::string& where) const {
  std::vector<double> normals;
  auto na = prim.attributes.find("NORMAL");
  if (na == prim.attributes.end()) return normals;
  requireFloat(na->second, where + ": NORMAL");
  int nc = 0;
  normals = readAccessor(na->second, where + " NORMAL", nc);
  if (nc != 3) fail(where + ": NORMAL is not VEC3");
  if (normals.size() / 3 != vertexCount) fail(where + ": NORMAL count differs from POSITION count");
  if (!allFinite(normals)) fail(where + ": non-finite normal");
  return normals;
}

// The primitive's indices, each checked against the vertex count; 0..n-1 without an accessor.
std::vector<uint32_t> Reader::readIndices(const tinygltf::Primitive& prim, size_t vertexCount,
                                          const std::string& where) const {
  std::vector<uint32_t> idx;
  if (prim.indices < 0) {
    idx.resize(vertexCount);
    for (size_t i = 0; i < vertexCount; ++i) idx[i] = uint32_t(i);
    return idx;
  }
  if (prim.indices >= int(m_.accessors.size())) fail(where + ": indices accessor out of range");
  const int ct = m_.accessors[size_t(prim.indices)].componentType;
  if (ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
      ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
    fail(where + ": index component type " + std::to_string(ct) + " not allowed");
  int nc = 0;
  std::vector<double> raw = readAccessor(prim.indices, where + " indices", nc);
  if (nc != 1) fail(where + ": indices are not SCALAR");
  idx.reserve(raw.size());
  for (double v : raw) {
    if (v >= double(vertexCount))
      fail(where + ": index " + std::to_string(uint64_t(v)) + " out of range (" +
           std::to_string(vertexCount) + " vertices)");
    idx.push_back(uint32_t(v));
  }
  return idx;
}

// rho = 1 reflects all it receives: with any emission the solve diverges (NaN or huge values).
// Clamped to kMaxReflectance, as the furnace's highest, with one warning.
void Reader::clampReflectance(Material& mat, const std::string& where, Scene& scene) const {
  const double before = std::max({mat.reflectance.x, mat.reflectance.y, mat.reflectance.z});
  if (before <= kMaxReflectance) return;
  mat.reflectance = glm::min(mat.reflectance, glm::dvec3(kMaxReflectance));
  scene.warnings.push_back(where + ": reflectance " + number(before) + " clamped to " +
                           number(kMaxReflectance) + " (the radiosity solve needs rho < 1)");
}

int Reader::material(int index, Scene& scene) {
  if (index < 0) return -1;  // glTF default material (§3.9.6): white, not emissive
  if (index >= int(m_.materials.size()))
    fail("material " + std::to_string(index) + " out of range");
  auto it = materialMap_.find(index);
  if (it != materialMap_.end()) return it->second;
  const tinygltf::Material& g = m_.materials[size_t(index)];
  const std::string where = gltfItemLabel("material", index, g.name);
  Material mat;
  mat.name = g.name;
  mat.gltfIndex = index;
  mat.doubleSided = g.doubleSided;
  const std::vector<double>& bc = g.pbrMetallicRoughness.baseColorFactor;
  if (bc.size() >= 3) {
    if (!allFinite(bc)) fail(where + ": non-finite baseColorFactor");
    for (int c = 0; c < 3; ++c) mat.reflectance[c] = std::clamp(bc[size_t(c)], 0.0, 1.0);
  }
  const tinygltf::TextureInfo& ti = g.pbrMetallicRoughness.baseColorTexture;
  if (ti.index >= 0) {
    mat.baseColorTexture = texture(ti.index, scene);
    mat.baseColorTexCoord = std::max(0, ti.texCoord);
    if (mat.baseColorTexture >= 0)
      mat.reflectance *= scene.textures[size_t(mat.baseColorTexture)].mean;
  }
  clampReflectance(mat, where, scene);
  double strength = 1.0;  // KHR_materials_emissive_strength
  auto ext = g.extensions.find("KHR_materials_emissive_strength");
  if (ext != g.extensions.end() && ext->second.Has("emissiveStrength")) {
    const tinygltf::Value& v = ext->second.Get("emissiveStrength");
    if (!v.IsNumber()) fail(where + ": emissiveStrength is not a number");
    strength = v.GetNumberAsDouble();
  }
  if (!std::isfinite(strength) || strength < 0.0)
    fail(where + ": emissiveStrength must be finite and >= 0");
  if (g.emissiveFactor.size() >= 3) {
    if (!allFinite(g.emissiveFactor)) fail(where + ": non-finite emissiveFactor");
    for (int c = 0; c < 3; ++c) {
      mat.emission[c] = std::max(0.0, g.emissiveFactor[size_t(c)]) * strength;
      // An emissiveStrength of 1e308 gave an infinite power and NaN radiosity with exit 0.
      if (!(mat.emission[c] <= kMaxEmission))
        fail(where + ": emission (emissiveFactor x emissiveStrength) " +
             number(g.emissiveFactor[size_t(c)] * strength) + " beyond the limit " +
             number(kMaxEmission) + " W m^-2 sr^-1");
    }
  }
  if (g.emissiveTexture.index >= 0 && mat.isEmitter()) {  // L_e x texture (emission_texture.h)
    mat.emissiveTexture = texture(g.emissiveTexture.index, scene);
    mat.emissiveTexCoord = std::max(0, g.emissiveTexture.texCoord);
  }
  scene.materials.push_back(mat);
  return materialMap_[index] = int(scene.materials.size()) - 1;
}

int Reader::texture(int index, Scene& scene) {
  if (index >= int(m_.textures.size())) fail("texture " + std::to_string(index) + " out of range");
  auto it = textureMap_.find(index);
  if (it != textureMap_.end()) return it->second;
  const tinygltf::Texture& gt = m_.textures[size_t(index)];
  const std::string where = gltfItemLabel("texture", index, gt.name);
  if (gt.source < 0 || gt.source >= int(m_.images.size())) {
    scene.warnings.push_back(where + ": no image source; base colour texture ignored");
    return textureMap_[index] = -1;
  }
  const tinygltf::Image& img = m_.images[size_t(gt.source)];
  const int w = img.width, h = img.height, comp = img.component, bits = img.bits;
  const size_t bytes = bits == 16 ? 2 : 1;
  if (w <= 0 || h <= 0 || comp < 1 || comp > 4 || (bits != 8 && bits != 16) ||
      img.image.size() < size_t(w) * size_t(h) * size_t(comp) * bytes) {
    // One rule for every image without pixels (formats/gltf_scene.md "Materials").
    std::string why = hooks_.imageProblem(size_t(gt.source));
    const std::string name = !img.name.empty() ? img.name : img.uri;
    scene.warnings.push_back(where + ": image " + std::to_string(gt.source) +
                             (name.empty() ? std::string() : " '" + clipInput(name) + "'") + ": " +
                             (why.empty() ? std::string("not decoded") : why) +
                             "; texture ignored, reflectance = baseColorFactor only");
    return textureMap_[index] = -1;
  }
  Texture tex;
  tex.name = img.name.empty() ? img.uri : img.name;
  tex.width = w;
  tex.height = h;
  tex.rgb.resize(size_t(w) * size_t(h) * 3);
  // sRGB transfer function inverse (IEC 61966-2-1), glTF §3.9.2: base colour textures are sRGB.
  auto toLinear = [](double c) {
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
  };
  double lut[256];
  for (int i = 0; i < 256; ++i) lut[i] = toLinear(i / 255.0);
  glm::dvec3 sum(0.0);
  for (size_t i = 0; i < size_t(w) * size_t(h); ++i) {
    double c[3];
    for (int k = 0; k < 3; ++k) {
      const int src = comp >= 3 ? k : 0;  // grey (+alpha) images replicate their first channel
      const size_t at = (i * size_t(comp) + size_t(src)) * bytes;
      if (bytes == 1) {
        c[k] = lut[img.image[at]];
      } else {
        uint16_t v;
        std::memcpy(&v, &img.image[at], 2);
        c[k] = toLinear(v / 65535.0);
      }
      tex.rgb[i * 3 + size_t(k)] = float(c[k]);
      sum[k] += c[k];
    }
  }
  tex.mean = sum / double(size_t(w) * size_t(h));
  scene.textures.push_back(std::move(tex));
  return textureMap_[index] = int(scene.textures.size()) - 1;
}

void Reader::readCameras(Scene& scene) {
  for (size_t i = 0; i < m_.cameras.size(); ++i) {
    const tinygltf::Camera& g = m_.cameras[i];
    const std::string where = gltfItemLabel("camera", int(i), g.name);
    Camera c;
    c.name = g.name;
    if (g.type == "perspective") {  // glTF §3.10
      c.perspective = true;
      c.yfov = g.perspective.yfov;
      c.aspectRatio = g.perspective.aspectRatio;
      c.znear = g.perspective.znear;
      c.zfar = g.perspective.zfar;
      if (!(c.yfov > 0.0 && c.yfov < M_PI)) fail(where + ": yfov must be in (0, pi)");
      if (c.yfov < kMinYfov)
        fail(where + ": yfov " + number(c.yfov) + " is below the limit " + number(kMinYfov) +
             " rad (0.057 degrees): the rasterising stages' float projection cannot place it");
      if (!(c.aspectRatio >= 0.0) || !std::isfinite(c.aspectRatio))
        fail(where + ": bad aspectRatio");
      if (!(c.znear > 0.0) || !std::isfinite(c.znear)) fail(where + ": znear must be > 0");
      if (!(c.zfar == 0.0 || (c.zfar > c.znear && std::isfinite(c.zfar))))
        fail(where + ": zfar must be greater than znear");
    } else if (g.type == "orthographic") {  // glTF §3.10
      c.perspective = false;
      c.xmag = g.orthographic.xmag;
      c.ymag = g.orthographic.ymag;
      c.znear = g.orthographic.znear;
      c.zfar = g.orthographic.zfar;
      if (!(std::isfinite(c.xmag) && std::isfinite(c.ymag) && c.xmag != 0.0 && c.ymag != 0.0))
        fail(where + ": xmag and ymag must be finite and non-zero");
      if (!(c.znear >= 0.0 && c.zfar > c.znear && std::isfinite(c.zfar)))
        fail(where + ": orthographic camera needs 0 <= znear < zfar");
    } else {
      fail(where + ": unknown type '" + clipInput(g.type) + "'");
    }
    scene.cameras.push_back(c);
  }
}

void Reader::readAnimations(Scene& scene) {
  for (size_t ai = 0; ai < m_.animations.size(); ++ai) {
    const tinygltf::Animation& ga = m_.animations[ai];
    for (size_t ci = 0; ci < ga.channels.size(); ++ci) {
      const tinygltf::AnimationChannel& gc = ga.channels[ci];
      const std::string where =
          gltfItemLabel("animation", int(ai), ga.name) + " channel " + std::to_string(ci);
      if (gc.target_node < 0) continue;  // glTF §3.11: no target node -> ignore the channel
      if (gc.target_node >= int(scene.nodes.size())) fail(where + ": target node out of range");
      AnimationChannel ch;
      ch.animation = ga.name;
      ch.node = gc.target_node;
      if (gc.target_path == "translation") {
        ch.path = AnimationPath::kTranslation;
      } else if (gc.target_path == "rotation") {
        ch.path = AnimationPath::kRotation;
      } else if (gc.target_path == "scale") {
        ch.path = AnimationPath::kScale;
      } else if (gc.target_path == "weights") {
        fail(where + ": animates morph target weights; morph targets are not supported");
      } else {
        fail(where + ": unknown target path '" + clipInput(gc.target_path) + "'");
      }
      if (m_.nodes[size_t(ch.node)].matrix.size() == 16)
        fail(where + ": targets " + nodeLabel(scene, ch.node) +
             " which has a matrix (glTF §3.11 forbids it)");
      if (gc.sampler < 0 || gc.sampler >= int(ga.samplers.size()))
        fail(where + ": sampler out of range");
      const tinygltf::AnimationSampler& gs = ga.samplers[size_t(gc.sampler)];
      if (gs.interpolation.empty() || gs.interpolation == "LINEAR") {
        ch.interpolation = Interpolation::kLinear;
      } else if (gs.interpolation == "STEP") {
        ch.interpolation = Interpolation::kStep;
      } else if (gs.interpolation == "CUBICSPLINE") {
        ch.interpolation = Interpolation::kCubicSpline;
      } else {
        fail(where + ": unknown interpolation '" + clipInput(gs.interpolation) + "'");
      }
      int nc = 0;
      ch.times = readAccessor(gs.input, where + " input", nc);
      if (nc != 1) fail(where + ": input is not SCALAR");
      if (ch.times.empty()) fail(where + ": no keys");
      if (!allFinite(ch.times)) fail(where + ": non-finite key time");
      for (size_t k = 1; k < ch.times.size(); ++k)
        if (!(ch.times[k] > ch.times[k - 1]))
          fail(where + ": key times are not strictly increasing");
      ch.values = readAccessor(gs.output, where + " output", nc);
      const int want = ch.path == AnimationPath::kRotation ? 4 : 3;
      if (nc != want)
        fail(where + ": output has " + std::to_string(nc) + " components, expected " +
             std::to_string(want));
      const size_t per = ch.interpolation == Interpolation::kCubicSpline ? 3 : 1;
      if (ch.values.size() != ch.times.size() * per * size_t(want))
        fail(where + ": output has " + std::to_string(ch.values.size() / size_t(want)) +
             " elements, expected " + std::to_string(ch.times.size() * per));
      if (!allFinite(ch.values)) fail(where + ": non-finite output value");
      scene.channels.push_back(std::move(ch));
    }
  }
}

namespace {

// Largest |translation| and |scale component| a node takes at rest and over its channels' keys,
// with CUBICSPLINE overshoot (|h10|, |h11| <= 4/27 of the key interval times the tangent).
struct NodeReach {
  double translation = 0.0, scale = 0.0;
};

std::vector<NodeReach> nodeReach(const Scene& scene) {
  std::vector<NodeReach> reach(scene.nodes.size());
  for (size_t i = 0; i < scene.nodes.size(); ++i) {
    const Node& n = scene.nodes[i];
    reach[i].translation = glm::length(n.translation);
    reach[i].scale = std::max({std::abs(n.scale.x), std::abs(n.scale.y), std::abs(n.scale.z)});
  }
  for (const AnimationChannel& ch : scene.channels) {
    if (ch.path == AnimationPath::kRotation || ch.node < 0 || ch.node >= int(reach.size()))
      continue;
    const bool cubic = ch.interpolation == Interpolation::kCubicSpline;
    double value = 0.0, tangent = 0.0, interval = 0.0;
    for (size_t e = 0; e * 3 + 2 < ch.values.size(); ++e) {
      const glm::dvec3 v(ch.values[3 * e], ch.values[3 * e + 1], ch.values[3 * e + 2]);
      const double size = ch.path == AnimationPath::kTranslation
                              ? glm::length(v)
                              : std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
      if (cubic && e % 3 != 1)
        tangent = std::max(tangent, size);
      else
        value = std::max(value, size);
    }
    for (size_t k = 1; k < ch.times.size(); ++k)
      interval = std::max(interval, ch.times[k] - ch.times[k - 1]);
    const double bound = cubic ? 2.0 * value + 8.0 / 27.0 * interval * tangent : value;
    double& r = ch.path == AnimationPath::kTranslation ? reach[size_t(ch.node)].translation
                                                       : reach[size_t(ch.node)].scale;
    r = std::max(r, bound);
  }
  return reach;
}

}  // namespace

// Every world coordinate, at every time, stays within kMaxCoordinate: a bound through the
// hierarchy |T0 + R0 S0 (T1 + R1 S1 (... p))| <= |T0| + s0 (|T1| + s1 (... |p|)). Coordinates of
// 1e38 made Embree abort (ray.valid()) and areas overflow. Then no mesh node's rest transform
// may flatten its triangles to zero (or non-finite) area: their normals would be NaN.
void Reader::checkWorldBounds(const Scene& scene) const {
  const std::vector<NodeReach> reach = nodeReach(scene);
  struct Frame {
    int node;
    double offset, scale;  // bound on the frame origin's distance, product of scales
  };
  std::vector<Frame> stack;
  for (int r : scene.roots.empty() ? scene.reachableNodes() : scene.roots)
    if (scene.nodes[size_t(r)].parent < 0) stack.push_back({r, 0.0, 1.0});
  const double t0 = scene.startTime();
  std::vector<char> seen(scene.nodes.size(), 0);
  while (!stack.empty()) {
    const Frame parent = stack.back();
    stack.pop_back();
    const int i = parent.node;
    if (seen[size_t(i)]) continue;
    seen[size_t(i)] = 1;
    const std::string where = nodeLabel(scene, i);
    const Node& n = scene.nodes[size_t(i)];
    const Frame f{i, parent.offset + parent.scale * reach[size_t(i)].translation,
                  parent.scale * reach[size_t(i)].scale};
    double extent = 0.0;
    if (n.mesh >= 0)
      for (const MeshTriangle& t : scene.meshes[size_t(n.mesh)].triangles)
        for (const glm::dvec3& p : t.p) extent = std::max(extent, glm::length(p));
    const double reachable = f.offset + f.scale * extent;
    if (!(reachable <= kMaxCoordinate))
      fail(where + ": world coordinates reach up to " + number(reachable) + " (from the " +
           "translations and scales of it and its parents, and its vertices), beyond the limit " +
           number(kMaxCoordinate));
    if (n.mesh >= 0) requireWorldArea(scene, i, t0);
    for (int c : n.children) stack.push_back({c, f.offset, f.scale});
  }
}

void Reader::requireWorldArea(const Scene& scene, int node, double t) const {
  const glm::dmat3 m(scene.worldTransform(node, t));
  const std::vector<MeshTriangle>& tris =
      scene.meshes[size_t(scene.nodes[size_t(node)].mesh)].triangles;
  for (size_t k = 0; k < tris.size(); ++k) {
    const glm::dvec3 a = m * (tris[k].p[1] - tris[k].p[0]), b = m * (tris[k].p[2] - tris[k].p[0]);
    const double twiceArea = glm::length(glm::cross(a, b));
    const double edge = std::max({glm::length(a), glm::length(b), glm::length(b - a)});
    if (!(twiceArea > 1e-12 * edge * edge) || !std::isfinite(twiceArea))
      fail(nodeLabel(scene, node) + ": its world transform (scale " +
           number(scene.nodes[size_t(node)].scale.x) + " " +
           number(scene.nodes[size_t(node)].scale.y) + " " +
           number(scene.nodes[size_t(node)].scale.z) + " with its parents') flattens triangle " +
           std::to_string(k) + " of mesh " + std::to_string(scene.nodes[size_t(node)].mesh) +
           " to zero area");
  }
}

GltfReadOptions& defaultGltfReadOptions() {
  static GltfReadOptions options;
  return options;
}

namespace {
GltfWarningHandler& warningHandler() {
  static GltfWarningHandler handler;
  return handler;
}

// tinygltf's warnings about external images (not found, unreadable, empty): the reader's own
// warning for the texture says the same with the reason, once.
std::string withoutImageFileWarnings(const std::string& warn) {
  std::istringstream lines(warn);
  std::string line, kept;
  while (std::getline(lines, line)) {
    bool fileLine = false;
    for (const char* prefix : {"File not found : ", "File read error : ", "File is empty : ",
                               "Failed to load external 'uri' for image["})
      fileLine = fileLine || line.rfind(prefix, 0) == 0;
    if (!fileLine) kept += line + "\n";
  }
  return kept;
}

Scene parseAndRead(const std::string& path, const GltfReadOptions& options) {
  const GltfSceneFile file = readGltfSceneFile(path);
  GltfLoaderHooks hooks(file.externalFiles, options.maxTexturePixels);
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  hooks.install(loader);
  std::string err, warn;
  bool ok = false;
  try {
    const auto* data = reinterpret_cast<const unsigned char*>(file.bytes.data());
    const auto size = static_cast<unsigned int>(file.bytes.size());  // <= kMaxSceneFileBytes
    ok = file.binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, data, size, file.baseDir)
                     : loader.LoadASCIIFromString(&model, &err, &warn, file.bytes.data(), size,
                                                  file.baseDir);
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {
    throw inputError(path, std::string("invalid gltf: ") + oneLine(e.what()));
  }
  if (!ok) {
    const std::string buffer = hooks.bufferProblem();
    if (!buffer.empty()) throw inputError(path, buffer);
    std::string what = oneLine(err.empty() ? warn : err);
    throw inputError(path, "invalid gltf: " + (what.empty() ? std::string("unknown error") : what));
  }
  Reader reader(path, model, options, hooks);
  Scene scene = reader.read();
  warn = withoutImageFileWarnings(warn);
  if (!warn.empty()) scene.warnings.push_back("tinygltf: " + oneLine(warn));
  return scene;
}
}  // namespace

void setGltfWarningHandler(GltfWarningHandler handler) {
  warningHandler() = std::move(handler);
}

Scene readGltfScene(const std::string& path) {
  return readGltfScene(path, defaultGltfReadOptions());
}

Scene readGltfScene(const std::string& path, const GltfReadOptions& options) {
  Scene scene;
  try {
    scene = parseAndRead(path, options);
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {  // exit 4 as documented, not bad input
    throw Error(ExitCode::kEnvironment, path, "out of memory while reading the scene");
  } catch (const std::exception& e) {  // a library's failure on absurd input: still bad input
    throw inputError(path, std::string("cannot read: ") + oneLine(e.what()));
  }
  if (warningHandler())
    for (const std::string& w : scene.warnings) warningHandler()(path, w);
  return scene;
}

}  // namespace rad
