#include "scene/object_mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <map>
#include <stdexcept>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <tiny_gltf.h>

#include "base/error.h"
#include "base/files.h"
#include "scene/model.h"

namespace daylit::scene {

Mesh SphereMesh(float radius, int stacks, int slices) {
  Mesh mesh;
  for (int i = 0; i <= stacks; ++i) {
    const float theta = glm::pi<float>() * static_cast<float>(i) / static_cast<float>(stacks);
    for (int j = 0; j <= slices; ++j) {
      // The seam's and the poles' copies of a vertex are exactly equal: the mesh is watertight.
      const float phi = 2.0f * glm::pi<float>() * static_cast<float>(j % slices) / static_cast<float>(slices);
      const float sin_theta = i == 0 || i == stacks ? 0.0f : std::sin(theta);
      const float cos_theta = i == 0 ? 1.0f : i == stacks ? -1.0f : std::cos(theta);
      const glm::vec3 n(sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta);
      mesh.positions.push_back(radius * n);
      mesh.normals.push_back(n);
    }
  }
  const auto at = [&](int i, int j) { return static_cast<uint32_t>(i * (slices + 1) + j); };
  for (int i = 0; i < stacks; ++i) {
    for (int j = 0; j < slices; ++j) {
      // Counter-clockwise from outside: θ grows downward from +Z, φ grows counter-clockwise.
      if (i > 0) mesh.indices.insert(mesh.indices.end(), {at(i, j), at(i + 1, j), at(i, j + 1)});
      if (i < stacks - 1) mesh.indices.insert(mesh.indices.end(), {at(i, j + 1), at(i + 1, j), at(i + 1, j + 1)});
    }
  }
  return mesh;
}

constexpr int kBoxGrid = 8;  // quads per face edge

Mesh BoxMesh(const glm::vec3& size) {
  Mesh mesh;
  const glm::vec3 h = 0.5f * size;
  for (int axis = 0; axis < 3; ++axis) {
    for (const float sign : {-1.0f, 1.0f}) {
      glm::vec3 n(0.0f);
      n[axis] = sign;
      const glm::vec3 u = axis == 2 ? glm::vec3(1, 0, 0) : glm::vec3(0, 0, 1);
      const glm::vec3 v = glm::cross(n, u);  // (u, v, n) right-handed: counter-clockwise from outside
      // Each face a grid of quads, so that what is interpolated across triangles (the volume's
      // light, the bounce losses) follows the surface; its parameters are exact binary fractions,
      // so the faces' shared edges have bit-identical vertices (a watertight mesh).
      const auto base = static_cast<uint32_t>(mesh.positions.size());
      const auto at = [&](int i, int j) { return base + static_cast<uint32_t>(j * (kBoxGrid + 1) + i); };
      for (int j = 0; j <= kBoxGrid; ++j) {
        for (int i = 0; i <= kBoxGrid; ++i) {
          const float a = -1.0f + 2.0f * static_cast<float>(i) / kBoxGrid, b = -1.0f + 2.0f * static_cast<float>(j) / kBoxGrid;
          mesh.positions.push_back(h * (n + a * u + b * v));
          mesh.normals.push_back(n);
        }
      }
      for (int j = 0; j < kBoxGrid; ++j) {
        for (int i = 0; i < kBoxGrid; ++i) {
          mesh.indices.insert(mesh.indices.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)});
        }
      }
    }
  }
  return mesh;
}

bool IsClosedMesh(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices) {
  std::map<std::array<float, 3>, uint32_t> weld;
  std::vector<uint32_t> id(positions.size());
  for (size_t v = 0; v < positions.size(); ++v) {
    const std::array<float, 3> key{positions[v].x, positions[v].y, positions[v].z};
    id[v] = weld.emplace(key, static_cast<uint32_t>(weld.size())).first->second;
  }
  std::map<std::pair<uint32_t, uint32_t>, int> edges;  // directed edge → how often
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    const uint32_t a = id[indices[t]], b = id[indices[t + 1]], c = id[indices[t + 2]];
    if (a == b || b == c || c == a) continue;
    for (const auto& e : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
      if (++edges[e] > 1) return false;
    }
  }
  for (const auto& [e, count] : edges) {
    if (edges.find({e.second, e.first}) == edges.end()) return false;
  }
  return !edges.empty();
}

namespace {

// The triangles as drawn, one vertex per corner, with the face's normal (counter-clockwise
// from outside), as the OBJ and glTF readers give them.
void AddFlatTriangle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, Mesh* mesh) {
  const glm::vec3 cross = glm::cross(b - a, c - a);
  const glm::vec3 n = glm::length(cross) > 0.0f ? glm::normalize(cross) : glm::vec3(0, 0, 1);
  for (const glm::vec3& p : {a, b, c}) {
    mesh->indices.push_back(static_cast<uint32_t>(mesh->positions.size()));
    mesh->positions.push_back(p);
    mesh->normals.push_back(n);
  }
}

// An accessor's elements as read through its buffer view: `count` × `size` bytes, `stride` apart.
const unsigned char* AccessorData(const tinygltf::Model& model, const tinygltf::Accessor& accessor, size_t size,
                                  size_t* stride, const std::string& where) {
  if (accessor.sparse.isSparse || accessor.bufferView < 0 || static_cast<size_t>(accessor.bufferView) >= model.bufferViews.size()) {
    ThrowInputError("{}: an accessor without a plain buffer view (sparse or missing) is not supported", where);
  }
  const tinygltf::BufferView& view = model.bufferViews[static_cast<size_t>(accessor.bufferView)];
  if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= model.buffers.size()) ThrowInputError("{}: a buffer view without a buffer", where);
  const std::vector<unsigned char>& data = model.buffers[static_cast<size_t>(view.buffer)].data;
  *stride = view.byteStride != 0 ? view.byteStride : size;
  const size_t begin = view.byteOffset + accessor.byteOffset;
  if (accessor.count > 0 && begin + (accessor.count - 1) * *stride + size > std::min(data.size(), view.byteOffset + view.byteLength)) {
    ThrowInputError("{}: an accessor runs past its buffer", where);
  }
  return data.data() + begin;
}

// A node's local transform: its matrix, or translation · rotation · scale.
glm::dmat4 NodeTransform(const tinygltf::Node& node) {
  glm::dmat4 local(1.0);
  if (node.matrix.size() == 16) {
    for (int c = 0; c < 4; ++c) {
      for (int r = 0; r < 4; ++r) local[c][r] = node.matrix[static_cast<size_t>(4 * c + r)];
    }
    return local;
  }
  if (node.translation.size() == 3) local = glm::translate(local, glm::dvec3(node.translation[0], node.translation[1], node.translation[2]));
  if (node.rotation.size() == 4) local *= glm::mat4_cast(glm::dquat(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]));
  if (node.scale.size() == 3) local = glm::scale(local, glm::dvec3(node.scale[0], node.scale[1], node.scale[2]));
  return local;
}

// A primitive's vertex order: its indices, or 0, 1, 2, ... without them.
std::vector<uint32_t> PrimitiveOrder(const tinygltf::Model& model, const tinygltf::Primitive& primitive, size_t vertices,
                                     const std::string& where) {
  std::vector<uint32_t> order;
  if (primitive.indices < 0) {
    for (size_t v = 0; v < vertices; ++v) order.push_back(static_cast<uint32_t>(v));
    return order;
  }
  if (static_cast<size_t>(primitive.indices) >= model.accessors.size()) ThrowInputError("{}: indices accessor missing", where);
  const tinygltf::Accessor& ia = model.accessors[static_cast<size_t>(primitive.indices)];
  const size_t size = ia.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ? 1
                      : ia.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? 2
                      : ia.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT ? 4 : 0;
  if (size == 0) ThrowInputError("{}: indices must be unsigned integers", where);
  size_t stride = 0;
  const unsigned char* idata = AccessorData(model, ia, size, &stride, where);
  for (size_t k = 0; k < ia.count; ++k) {
    uint32_t i = 0;
    std::memcpy(&i, idata + k * stride, size);  // little-endian, as glTF is
    if (i >= vertices) ThrowInputError("{}: index {} past the {} vertices", where, i, vertices);
    order.push_back(i);
  }
  return order;
}

// A triangle primitive under the node's `world` transform, into `mesh` in scene coordinates:
// glTF's +Y up turned to +Z up, (x, y, z) → (x, −z, y).
void AddPrimitive(const tinygltf::Model& model, const tinygltf::Primitive& primitive, const glm::dmat4& world,
                  const std::string& where, Mesh* mesh) {
  const glm::dmat4 y_up_to_z_up(1, 0, 0, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1);  // columns
  const auto position = primitive.attributes.find("POSITION");
  if (position == primitive.attributes.end() || position->second < 0 ||
      static_cast<size_t>(position->second) >= model.accessors.size()) {
    ThrowInputError("{}: a primitive without POSITION", where);
  }
  const tinygltf::Accessor& pa = model.accessors[static_cast<size_t>(position->second)];
  if (pa.type != TINYGLTF_TYPE_VEC3 || pa.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT) {
    ThrowInputError("{}: POSITION must be float VEC3", where);
  }
  size_t stride = 0;
  const unsigned char* pdata = AccessorData(model, pa, 12, &stride, where);
  std::vector<glm::vec3> points(pa.count);
  for (size_t v = 0; v < pa.count; ++v) {
    glm::vec3 p;
    std::memcpy(&p, pdata + v * stride, 12);
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) ThrowInputError("{}: vertex {} is not finite", where, v);
    points[v] = glm::vec3(y_up_to_z_up * world * glm::dvec4(glm::dvec3(p), 1.0));
  }
  const std::vector<uint32_t> order = PrimitiveOrder(model, primitive, points.size(), where);
  // A mirroring transform turns the winding; keep the faces counter-clockwise from outside.
  const bool mirrored = glm::determinant(glm::dmat3(world)) < 0.0;
  for (size_t k = 0; k + 2 < order.size(); k += 3) {
    const glm::vec3 &a = points[order[k]], &b = points[order[k + 1]], &c = points[order[k + 2]];
    if (mirrored) {
      AddFlatTriangle(a, c, b, mesh);
    } else {
      AddFlatTriangle(a, b, c, mesh);
    }
  }
}

// The files a glTF names (buffers, images), as tinygltf opens them: joined to the glTF's folder
// and percent-decoded by tinygltf, then held to `root` here, as written and where it leads, so
// that a uri "../../etc/passwd" or "%2e%2e/...", or a link in the folder to a file outside it, is
// refused, not read (a model file from elsewhere names them). No "~" expansion.
struct GltfFiles {
  std::filesystem::path root;  // empty: anywhere
  std::string refused;         // the first path refused

  bool Allows(const std::string& file) {
    if (root.empty()) return true;
    const std::filesystem::path rel = std::filesystem::absolute(file).lexically_normal().lexically_relative(root);
    if (!rel.empty() && *rel.begin() != ".." && IsWithin(file, root)) return true;
    if (refused.empty()) refused = file;
    return false;
  }
  // Only a regular file: tinygltf sizes a file by seeking to its end, and a folder on ext4 seeks
  // to 2^63 - 1 (a uri "" or "." names the glTF's own folder), a request for that many bytes.
  static bool IsFile(const std::string& file) {
    std::error_code error;
    return std::filesystem::is_regular_file(file, error);
  }
  static bool Exists(const std::string& file, void* self) {
    return static_cast<GltfFiles*>(self)->Allows(file) && IsFile(file);
  }
  static std::string Expand(const std::string& file, void*) { return file; }
  static bool Read(std::vector<unsigned char>* out, std::string* err, const std::string& file, void* self) {
    if (!static_cast<GltfFiles*>(self)->Allows(file)) return false;
    if (!IsFile(file)) {
      if (err != nullptr) *err += "'" + file + "' is not a file\n";
      return false;
    }
    return tinygltf::ReadWholeFile(out, err, file, nullptr);
  }
  static bool Write(std::string*, const std::string&, const std::vector<unsigned char>&, void*) { return false; }
};

// A glTF 2.0 file's triangles in its default scene, node transforms applied, in scene
// coordinates (AddPrimitive). Its buffers and images must lie in `root` (empty: anywhere).
Mesh LoadGltfMesh(const std::filesystem::path& path, const std::filesystem::path& root) {
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  GltfFiles files{root.empty() ? root : std::filesystem::absolute(root).lexically_normal(), {}};
  loader.SetFsCallbacks({&GltfFiles::Exists, &GltfFiles::Expand, &GltfFiles::Read, &GltfFiles::Write, &files});
  std::string error, warning;
  bool ok = false;
  try {
    ok = path.extension() == ".glb" ? loader.LoadBinaryFromFile(&model, &error, &warning, path.string())
                                    : loader.LoadASCIIFromFile(&model, &error, &warning, path.string());
  } catch (const std::out_of_range& e) {
    // tinygltf indexes some of the file's own lists with at(): a .glb whose buffer has byteLength
    // 0 and no binary chunk asked for element 0 of an empty one (fuzz_gltf).
    ThrowInputError("{}: not a glTF 2.0 file (an index past one of its lists: {})", path.string(), e.what());
  }
  if (!files.refused.empty()) {
    ThrowInputError("{}: names '{}', outside the recording folder {} (daylit --allow-outside-paths allows it)", path.string(),
                    files.refused, files.root.string());
  }
  if (!ok) ThrowInputError("{}: not a glTF 2.0 file ({})", path.string(), error.empty() ? "unreadable" : error.substr(0, error.find('\n')));
  const std::string where = path.string();
  Mesh mesh;
  std::function<void(int, const glm::dmat4&)> visit = [&](int index, const glm::dmat4& parent) {
    if (index < 0 || static_cast<size_t>(index) >= model.nodes.size()) ThrowInputError("{}: node {} does not exist", where, index);
    const tinygltf::Node& node = model.nodes[static_cast<size_t>(index)];
    const glm::dmat4 world = parent * NodeTransform(node);
    if (node.mesh >= 0) {
      if (static_cast<size_t>(node.mesh) >= model.meshes.size()) ThrowInputError("{}: mesh {} does not exist", where, node.mesh);
      for (const tinygltf::Primitive& primitive : model.meshes[static_cast<size_t>(node.mesh)].primitives) {
        if (primitive.mode != -1 && primitive.mode != TINYGLTF_MODE_TRIANGLES) continue;  // points, lines, strips
        AddPrimitive(model, primitive, world, where, &mesh);
      }
    }
    for (const int child : node.children) visit(child, world);
  };
  if (!model.scenes.empty()) {
    const size_t scene = model.defaultScene >= 0 ? static_cast<size_t>(model.defaultScene) : 0;
    if (scene >= model.scenes.size()) ThrowInputError("{}: scene {} does not exist", where, scene);
    for (const int node : model.scenes[scene].nodes) visit(node, glm::dmat4(1.0));
  } else {
    for (size_t n = 0; n < model.nodes.size(); ++n) visit(static_cast<int>(n), glm::dmat4(1.0));
  }
  if (mesh.indices.empty()) ThrowInputError("{}: no triangles", where);
  return mesh;
}

}  // namespace

// Below 48 slices (7.5° a facet) the interpolated normals of a small sphere stray enough to show
// in its shading (percents of n·l), whatever its size in pixels.
constexpr int kMinShadingSlices = 48;

Mesh ShadingMesh(const VirtualObject& object, const Scene& scene) {
  if (object.kind != MeshKind::kSphere) return ObjectMesh(object);
  const double r = object.radius * std::max({object.scale.x, object.scale.y, object.scale.z});
  const double depth = (scene.cam_from_world.rotation * object.position + scene.cam_from_world.translation).z - r;
  if (!(depth > 1e-3)) return ObjectMesh(object);  // reaching the camera: the full mesh
  const double r_px = std::max(scene.intrinsics.fx, scene.intrinsics.fy) * r / depth;
  const int n = r_px <= 0.1 ? 0 : static_cast<int>(std::ceil(glm::pi<double>() / std::acos(1.0 - 0.1 / r_px)));
  return ObjectMesh(object, std::clamp(n + n % 2, kMinShadingSlices, kSphereSlices));
}

Mesh ObjectMesh(const VirtualObject& object, int sphere_slices) {
  Mesh mesh;
  switch (object.kind) {
    case MeshKind::kSphere: mesh = SphereMesh(static_cast<float>(object.radius), sphere_slices / 2, sphere_slices); break;
    case MeshKind::kBox: mesh = BoxMesh(glm::vec3(object.size)); break;
    case MeshKind::kFile: {
      if (object.file.extension() != ".obj") {
        mesh = LoadGltfMesh(object.file, object.resource_root);
        break;
      }
      const SceneModel model = LoadObjModel(object.file);
      if (model.triangles.empty()) ThrowInputError("{}: no triangles", object.file.string());
      for (const Triangle& t : model.triangles) AddFlatTriangle(model.vertices[t.v[0]], model.vertices[t.v[1]], model.vertices[t.v[2]], &mesh);
      break;
    }
  }
  const glm::dvec3 r = glm::radians(object.rotation_deg);
  glm::dmat4 m = glm::translate(glm::dmat4(1.0), object.position);
  m = glm::rotate(m, r.z, glm::dvec3(0, 0, 1));
  m = glm::rotate(m, r.y, glm::dvec3(0, 1, 0));
  m = glm::rotate(m, r.x, glm::dvec3(1, 0, 0));
  m = glm::scale(m, object.scale);
  const glm::mat3 normal_matrix = glm::mat3(glm::transpose(glm::inverse(glm::dmat3(m))));
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    mesh.positions[i] = glm::vec3(m * glm::dvec4(glm::dvec3(mesh.positions[i]), 1.0));
    mesh.normals[i] = glm::normalize(normal_matrix * mesh.normals[i]);
  }
  return mesh;
}

void CheckObjectsOutsideModel(const SceneModel& objects, const RayCaster& real, const std::string& where) {
  constexpr int kRays = 64;
  std::vector<glm::vec3> lo, hi;
  objects.SurfaceBounds(&lo, &hi);
  for (size_t o = 0; o < lo.size(); ++o) {
    if (lo[o].x > hi[o].x) continue;  // no triangles
    const glm::vec3 centre = 0.5f * (lo[o] + hi[o]);
    int back = 0;
    std::map<uint32_t, int> surfaces;
    for (int k = 0; k < kRays; ++k) {
      // A Fibonacci sphere of directions.
      const float z = 1.0f - 2.0f * (static_cast<float>(k) + 0.5f) / kRays;
      const float r = std::sqrt(std::max(0.0f, 1.0f - z * z)), phi = 2.39996323f * static_cast<float>(k);
      const RayHit hit = real.Intersect(centre, glm::vec3(r * std::cos(phi), r * std::sin(phi), z));
      if (hit.IsHit() && hit.back_face) ++back, ++surfaces[hit.surface];
    }
    if (back * 10 < kRays * 9) continue;
    const auto most = std::max_element(surfaces.begin(), surfaces.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
    ThrowInputError("{}: objects[{}]: its centre ({:.2f}, {:.2f}, {:.2f}) is inside the model (surface '{}'); move it out",
                    where, o, centre.x, centre.y, centre.z, real.model().surface_names[most->first]);
  }
}

SceneModel ObjectsModel(const std::vector<VirtualObject>& objects) {
  SceneModel model;
  for (size_t o = 0; o < objects.size(); ++o) {
    const Mesh mesh = ObjectMesh(objects[o]);
    const auto base = static_cast<uint32_t>(model.vertices.size());
    model.vertices.insert(model.vertices.end(), mesh.positions.begin(), mesh.positions.end());
    for (size_t t = 0; t < mesh.indices.size(); t += 3) {
      model.triangles.push_back({{base + mesh.indices[t], base + mesh.indices[t + 1], base + mesh.indices[t + 2]},
                                 static_cast<uint32_t>(o)});
    }
    model.surface_names.push_back("object_" + std::to_string(o));
  }
  model.file = "objects";
  return model;
}

}  // namespace daylit::scene
