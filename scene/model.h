// The real scene's geometry: a triangle mesh in scene coordinates (metres, +Z up), each triangle
// tagged with the surface (OBJ `o`/`g` name) it belongs to.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace daylit::scene {

struct Triangle {
  uint32_t v[3];
  uint32_t surface;  // index into SceneModel::surface_names
};

struct SceneModel {
  std::filesystem::path file;
  std::vector<glm::vec3> vertices;
  std::vector<Triangle> triangles;
  std::vector<std::string> surface_names;  // unique, in order of first appearance

  // Index of surface `name`, or -1.
  int SurfaceIndex(const std::string& name) const;
  // Surfaces whose names match a shell-style glob (fnmatch), in surface order.
  std::vector<int> MatchSurfaces(const std::string& glob) const;
  // Axis-aligned bounds of all vertices.
  void Bounds(glm::vec3* lo, glm::vec3* hi) const;
  // The same per surface, over its triangles' vertices (lo > hi for a surface with none).
  void SurfaceBounds(std::vector<glm::vec3>* lo, std::vector<glm::vec3>* hi) const;
  // Total area in m² of each surface's triangles.
  std::vector<double> SurfaceAreas() const;
};

// Loads a Wavefront OBJ (tinyobjloader, triangulated). Materials are ignored. Throws InputError
// naming the file and line for an unreadable file, non-finite vertex coordinates, face indices
// out of range, or a model with no faces.
SceneModel LoadObjModel(const std::filesystem::path& path);

}  // namespace daylit::scene
