#include "scene/object_mesh.h"

#include <array>
#include <cmath>
#include <map>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "base/error.h"
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

Mesh ObjectMesh(const VirtualObject& object) {
  Mesh mesh;
  switch (object.kind) {
    case MeshKind::kSphere: mesh = SphereMesh(static_cast<float>(object.radius), 48, 96); break;
    case MeshKind::kBox: mesh = BoxMesh(glm::vec3(object.size)); break;
    case MeshKind::kFile: {
      const std::string ext = object.file.extension().string();
      if (ext != ".obj") ThrowInputError("{}: only OBJ meshes are read so far", object.file.string());
      const SceneModel model = LoadObjModel(object.file);
      if (model.triangles.empty()) ThrowInputError("{}: no triangles", object.file.string());
      for (const Triangle& t : model.triangles) {
        const glm::vec3 a = model.vertices[t.v[0]], b = model.vertices[t.v[1]], c = model.vertices[t.v[2]];
        const glm::vec3 cross = glm::cross(b - a, c - a);
        const glm::vec3 n = glm::length(cross) > 0.0f ? glm::normalize(cross) : glm::vec3(0, 0, 1);
        for (const glm::vec3& p : {a, b, c}) {
          mesh.indices.push_back(static_cast<uint32_t>(mesh.positions.size()));
          mesh.positions.push_back(p);
          mesh.normals.push_back(n);
        }
      }
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
